//! Benchmark of the polyhedra plugin (docs/PERFORMANCE.md, "Polyhedra"):
//!
//! 1. the narrow phase per pair of bricks (0.2 × 0.1 × 0.05 m, 8 vertices, 6 faces,
//!    12 edges): face–face in contact (4 points), turned by 0.01 rad about the
//!    common normal (an octagonal overlap, 4 points kept), edge–edge, separated
//!    within the alert distance, and separated beyond it (rejected on a face axis);
//! 2. a running-bond wall of `courses` × `bricks` bricks on a fixed base slab
//!    (default 20 × 50 = 1 010 bricks), QM/16 at 1.666e-4, h = 1e-3 s, one domain:
//!    mean time per step of each stage.
//!
//!     cargo run --release -p nscdd-polyhedra --example bench_poly [steps] [courses] [bricks]
use nscdd::dim::rotation::from_rotation_vector;
use nscdd::registry::RawContact3;
use nscdd_polyhedra::detect::{poly_poly, PolyScratch};
use nscdd_polyhedra::generate::box_points;
use nscdd_polyhedra::shapes::Poly;
use std::hint::black_box;
use std::time::Instant;

fn per_pair(name: &str, p: &Poly, xj: [f64; 3], rj: [f64; 3]) {
    let (xi, qi) = ([0.0; 3], [1.0, 0.0, 0.0, 0.0]);
    let qj = from_rotation_vector(rj);
    let mut out: Vec<RawContact3> = Vec::with_capacity(16);
    let mut sc = PolyScratch::default();
    let n = 200_000;
    let mut points = 0;
    let t = Instant::now();
    for _ in 0..n {
        out.clear();
        poly_poly(p, black_box(xi), qi, p, black_box(xj), qj, 0, 1, 0.002, &mut sc, &mut out);
        points = out.len();
    }
    let ns = t.elapsed().as_secs_f64() / n as f64 * 1e9;
    println!("| {name} | {points} | {ns:.0} |");
}

fn main() {
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|s| s.parse().ok()).collect();
    let steps = args.first().copied().unwrap_or(20);
    let courses = args.get(1).copied().unwrap_or(20);
    let bricks = args.get(2).copied().unwrap_or(50);

    let (l, w, h) = (0.2, 0.1, 0.05);
    let (p, _, _) = Poly::from_points(&box_points([-0.5 * l, -0.5 * w, -0.5 * h], [0.5 * l, 0.5 * w, 0.5 * h])).unwrap();
    println!("| brick pair | points | ns per pair |\n|---|---|---|");
    per_pair("face–face, in contact", &p, [0.05, 0.0, h], [0.0; 3]);
    per_pair("face–face, turned 0.01 rad", &p, [0.0, 0.0, h], [0.0, 0.0, 0.01]);
    per_pair("edge–edge (crossed, on edge)", &p, [0.0, 0.0, h + 0.0005], [0.3, 0.0, 1.5707963]);
    per_pair("separated 1 mm (< alert)", &p, [0.05, 0.0, h + 0.001], [0.0; 3]);
    per_pair("separated 1 cm (> alert)", &p, [0.05, 0.0, h + 0.01], [0.0; 3]);

    let text = format!(
        r#"dimension = 3
gravity = [0.0, 0.0, -9.81]
[time]
step = 1e-3
theta = 0.5
steps = {steps}
[solver]
norm = "QM/16"
tolerance = 1.666e-4
max_sweeps = 5000
[detection]
alert = 0.002
[[materials]]
name = "brick"
density = 1800.0
[[materials]]
name = "base"
density = 2400.0
[[laws]]
materials = ["brick", "brick"]
friction = 0.6
[[laws]]
materials = ["brick", "base"]
friction = 0.6
[[laws]]
materials = ["base", "base"]
law = "none"
[[generate]]
kind = "brick_wall"
material = "brick"
base_material = "base"
brick = [{l}, {w}, {h}]
courses = {courses}
bricks = {bricks}
"#
    );
    let t = Instant::now();
    let mut world = match nscdd::scene::Scene3::load_str(&text, "bench.toml", &nscdd_polyhedra::registry()) {
        Ok(s) => s.world,
        Err(e) => panic!("{e}"),
    };
    let load = t.elapsed().as_secs_f64();
    let (mut det, mut del, mut nlgs, mut upd, mut sweeps, mut contacts) = (0.0, 0.0, 0.0, 0.0, 0, 0);
    let t = Instant::now();
    for _ in 0..steps {
        let r = world.step().expect("the wall stands");
        det += r.times.detect;
        del += r.times.delassus;
        nlgs += r.times.nlgs;
        upd += r.times.update;
        sweeps += r.solve.sweeps;
        contacts = r.contacts;
    }
    let total = t.elapsed().as_secs_f64();
    let ms = |x: f64| 1e3 * x / steps as f64;
    println!(
        "\nwall {courses} × {bricks} ({} bodies), {contacts} contacts, load {load:.2} s, {steps} steps: {:.2} ms/step \
         (free velocity + detection {:.2}, W and targets {:.2}, NLGS {:.2} for {:.0} sweeps, update {:.2})",
        world.bodies.len(),
        ms(total),
        ms(det),
        ms(del),
        ms(nlgs),
        sweeps as f64 / steps as f64,
        ms(upd)
    );
}
