//! `nscdd bench`: the figures of docs/PERFORMANCE.md.
//!
//! - `nlgs`: NLGS throughput, contact updates per second on one thread, on a dense
//!   packing (a triangular lattice of touching disks resting in a box under gravity,
//!   settled for a few steps so that every contact carries load), timing plain
//!   sweeps of the solver's hot loop.
//! - `deposit`: time per step of a deposit split by stage (detection, Delassus
//!   blocks, NLGS, update, output), from the example scene's settings.

use nscdd::registry::Registry;
use nscdd::rigid2d::nlgs;
use std::time::Instant;

fn lattice_scene(n: usize) -> String {
    let nx = (n as f64).sqrt().round().max(2.0) as usize;
    let ny = n.div_ceil(nx);
    let r = 0.01;
    let w = 2.0 * r * nx as f64 + r;
    format!(
        r#"
[time]
step = 1e-3
steps = 1
[solver]
tolerance = 1e-4
max_sweeps = 200
[[materials]]
name = "g"
density = 1000.0
[[laws]]
materials = ["g", "g"]
friction = 0.3
[[bodies]]
shape = "wall"
material = "g"
position = [{cx}, {fy}]
length = {wl}
thickness = {r}
fixed = true
[[bodies]]
shape = "wall"
material = "g"
position = [{lx}, {cy}]
rotation = 1.5707963267948966
length = {hl}
thickness = {r}
fixed = true
[[bodies]]
shape = "wall"
material = "g"
position = [{rx}, {cy}]
rotation = 1.5707963267948966
length = {hl}
thickness = {r}
fixed = true
[[generate]]
kind = "triangular_lattice"
material = "g"
nx = {nx}
ny = {ny}
radius = {r}
origin = [{r}, {r}]
"#,
        cx = w / 2.0,
        fy = -r / 2.0,
        wl = w + 4.0 * r,
        lx = -r / 2.0,
        rx = w + r / 2.0,
        cy = ny as f64 * r * 1.8 / 2.0,
        hl = ny as f64 * r * 1.8 + 4.0 * r,
    )
}

/// NLGS contact updates per second on one thread.
pub fn nlgs(reg: &Registry, n: usize, sweeps: usize) {
    let mut s = nscdd::scene::load_str(&lattice_scene(n), "bench-lattice", reg).expect("bench scene");
    let w = &mut s.world;
    for _ in 0..5 {
        w.step().expect("bench step");
    }
    // one more step's contact set, solved by timed plain sweeps
    let c = &mut w.contacts;
    let mut order = vec![];
    nlgs::make_order(&mut order, c.len(), &w.solver, 0);
    let mut vel = w.bodies.vel.clone();
    let t = Instant::now();
    for _ in 0..sweeps {
        nlgs::sweep(c, &mut vel, &w.bodies.inv_mass, &order, 1.0, None);
    }
    let dt = t.elapsed().as_secs_f64();
    let updates = (c.len() * sweeps) as f64;
    println!(
        "{{\"bench\":\"nlgs\",\"bodies\":{},\"contacts\":{},\"sweeps\":{},\"seconds\":{:.4},\"updates_per_second\":{:.4e},\"ns_per_update\":{:.2}}}",
        w.bodies.len(),
        c.len(),
        sweeps,
        dt,
        updates / dt,
        1e9 * dt / updates
    );
}

/// Time per step of the deposit example, by stage.
pub fn deposit(reg: &Registry, n: usize, steps: usize) {
    let path = std::path::Path::new("examples/scenes/deposit.toml");
    let text = std::fs::read_to_string(path).expect("run from the repository root: examples/scenes/deposit.toml");
    let text = text.replace("count = 1000", &format!("count = {n}"));
    let mut s = nscdd::scene::load_str(&text, "deposit.toml", reg).expect("deposit scene");
    let dir = std::env::temp_dir().join(format!("nscdd-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let mut vtk = (reg.writer("vtk").expect("vtk writer"))();
    let every = s.output.every.max(1) as usize;
    let (mut det, mut del, mut sol, mut upd, mut out, mut sweeps, mut contacts) = (0.0, 0.0, 0.0, 0.0, 0.0, 0u64, 0usize);
    let t_all = Instant::now();
    for k in 1..=steps {
        let r = s.world.step().expect("deposit step");
        det += r.times.detect;
        del += r.times.delassus;
        sol += r.times.nlgs;
        upd += r.times.update;
        sweeps += r.solve.sweeps as u64;
        contacts = r.contacts;
        let t = Instant::now();
        if k % every == 0 {
            vtk.write(&s.world, &dir, k as u32).expect("vtk");
            std::hint::black_box(nscdd::output::final_json(&s.world));
        }
        out += t.elapsed().as_secs_f64();
    }
    let total = t_all.elapsed().as_secs_f64();
    let _ = std::fs::remove_dir_all(&dir);
    let ms = |x: f64| 1e3 * x / steps as f64;
    println!(
        "{{\"bench\":\"deposit\",\"bodies\":{},\"steps\":{},\"final_contacts\":{},\"mean_sweeps\":{:.1},\"ms_per_step\":{{\"detection\":{:.4},\"delassus\":{:.4},\"nlgs\":{:.4},\"update\":{:.4},\"output\":{:.4},\"total\":{:.4}}}}}",
        s.world.bodies.len(),
        steps,
        contacts,
        sweeps as f64 / steps as f64,
        ms(det),
        ms(del),
        ms(sol),
        ms(upd),
        ms(out),
        ms(total)
    );
}
