//! 3D physics validation with the spheres plugin: a sphere on an incline (slide and
//! roll thresholds and accelerations), a column of spheres (exact weights), a sphere
//! against a box wall, and the outputs of a 3D run.
//!
//! The incline's normal is n = (sin α, 0, cos α) (a plane rotated by α about y),
//! the downhill direction s = (cos α, 0, −sin α), gravity (0, 0, −g). A single
//! sphere–plane contact has the diagonal isotropic Delassus block
//! W = diag(1/m, 1/m + R²/I, 1/m + R²/I) (1/m in the tangent plane when rotations are
//! driven), solved in closed form by the one-contact solver; with θ = ½ the
//! position update is exact for a constant acceleration, so the measured
//! accelerations match the analytic ones to rounding (relative 1e-9).

use nscdd::scene::Scene3;

const G: f64 = 9.81;
const R: f64 = 0.05;
const RHO: f64 = 2500.0;

fn load(text: &str) -> Scene3 {
    let reg = nscdd_spheres::registry();
    nscdd::scene::Scene3::load_str(text, "test3.toml", &reg).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn steps(s: &mut Scene3, n: usize) {
    for _ in 0..n {
        let r = s.world.step().unwrap();
        assert!(r.solve.converged, "step {} did not converge: {:?}", s.world.step, r.solve);
    }
}

/// A sphere at rest touching the incline of angle α, friction μ; `locked` drives its
/// rotations to 0 (a sliding block).
fn incline(alpha: f64, mu: f64, locked: bool) -> Scene3 {
    let (sa, ca) = alpha.sin_cos();
    let drive = if locked {
        "drive = { rx = { velocity = 0.0 }, ry = { velocity = 0.0 }, rz = { velocity = 0.0 } }"
    } else {
        ""
    };
    load(&format!(
        r#"
dimension = 3
[time]
step = 1e-3
steps = 400
[solver]
tolerance = 1e-10
[[materials]]
name = "m"
density = {RHO:?}
[[laws]]
materials = ["m", "m"]
friction = {mu:?}
[[bodies]]
name = "slope"
shape = "plane"
material = "m"
position = [0.0, 0.0, 0.0]
rotation = [0.0, {alpha:?}, 0.0]
fixed = true
[[bodies]]
name = "ball"
shape = "sphere"
material = "m"
radius = {R:?}
position = [{:?}, 0.0, {:?}]
{drive}
"#,
        sa * R,
        ca * R
    ))
}

/// Acceleration along the slope over the run (from the displacement, s = ½ a T²).
fn downhill_acceleration(s: &mut Scene3, n: usize) -> f64 {
    let alpha_pos = s.world.bodies.pos[1];
    steps(s, n);
    let p = s.world.bodies.pos[1];
    let n_hat = nscdd::dim::rotation::rotate(s.world.bodies.rot[0], [0.0, 0.0, 1.0]);
    let sdir = [n_hat[2], 0.0, -n_hat[0]];
    let d: f64 = (0..3).map(|k| (p[k] - alpha_pos[k]) * sdir[k]).sum();
    let t = s.world.t;
    2.0 * d / (t * t)
}

fn rel(what: &str, got: f64, want: f64, tol: f64) {
    let e = (got - want).abs() / want.abs().max(1e-300);
    println!("{what}: measured {got:.12e}, expected {want:.12e}, rel. error {e:.2e}");
    assert!(e <= tol, "{what}: {got} vs {want} (rel. error {e:e} > {tol:e})");
}

#[test]
fn locked_sphere_slides_iff_tan_alpha_exceeds_mu() {
    let mu: f64 = 0.4;
    let alpha = mu.atan();
    // 1° below: sticks (the contact holds it exactly)
    let mut s = incline(alpha - 1f64.to_radians(), mu, true);
    let a = downhill_acceleration(&mut s, 300);
    println!("1° below tan α = μ: a = {a:e}");
    assert!(a.abs() < 1e-9, "a locked sphere below the threshold must stick, a = {a}");
    // 1° above: slides with a = g (sin α − μ cos α)
    let al = alpha + 1f64.to_radians();
    let mut s = incline(al, mu, true);
    let a = downhill_acceleration(&mut s, 300);
    rel("locked sphere sliding", a, G * (al.sin() - mu * al.cos()), 1e-9);
}

#[test]
fn free_sphere_rolls_iff_mu_exceeds_two_sevenths_tan_alpha() {
    let alpha = 30f64.to_radians();
    let mu_star = 2.0 / 7.0 * alpha.tan();
    // above μ*: rolls without slipping, a = 5/7 g sin α, ω R = v
    let mut s = incline(alpha, 1.05 * mu_star, false);
    let a = downhill_acceleration(&mut s, 300);
    rel("rolling sphere", a, 5.0 / 7.0 * G * alpha.sin(), 1e-9);
    let v = s.world.bodies.vel[1];
    let speed = (v[0] * v[0] + v[2] * v[2]).sqrt();
    rel("no slip: |ω| R = |v|", v[4].abs() * R, speed, 1e-9);
    // below μ*: slips, a = g (sin α − μ cos α)
    let mu = 0.95 * mu_star;
    let mut s = incline(alpha, mu, false);
    let a = downhill_acceleration(&mut s, 300);
    rel("slipping sphere", a, G * (alpha.sin() - mu * alpha.cos()), 1e-9);
    let v = s.world.bodies.vel[1];
    let speed = (v[0] * v[0] + v[2] * v[2]).sqrt();
    assert!(v[4].abs() * R < 0.99 * speed, "a slipping sphere turns slower than it rolls");
}

#[test]
fn column_of_spheres_carries_exact_weights() {
    let n = 10;
    let mut s = load(&format!(
        r#"
dimension = 3
[time]
step = 1e-3
steps = 10
[solver]
tolerance = 1e-12
max_sweeps = 100000
norm = "Quad"
[[materials]]
name = "m"
density = {RHO:?}
[[laws]]
materials = ["m", "m"]
friction = 0.5
[[bodies]]
name = "floor"
shape = "plane"
material = "m"
position = [0.0, 0.0, 0.0]
fixed = true
[[generate]]
kind = "sphere_lattice"
material = "m"
nx = 1
nz = {n}
radius = {R:?}
origin = [0.0, 0.0, {R:?}]
"#
    ));
    steps(&mut s, 10);
    let w = &s.world;
    let m = w.bodies.mass[1];
    let h = w.time.h;
    // the contact under sphere k (counted from the top, 1-based) carries k m g
    let c = &w.contacts;
    assert_eq!(c.len(), n);
    for a in 0..c.len() {
        let [i, j] = c.bodies[a];
        let lower = i.min(j) as usize; // the floor is body 0, spheres bottom-up
        let above = n - lower; // spheres resting on this contact
        let f = c.r[a][0] / h;
        rel(&format!("contact under {above} spheres"), f, above as f64 * m * G, 1e-9);
        assert!(
            c.r[a][1].abs() + c.r[a][2].abs() <= 1e-12 * c.r[a][0],
            "no friction in a vertical column"
        );
    }
    let v = w
        .bodies
        .vel
        .iter()
        .skip(1)
        .map(|v| v.iter().map(|x| x.abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    assert!(v < 1e-12, "the column is at rest, max |V| = {v}");
}

#[test]
fn sphere_rests_on_a_box_and_the_run_writes_outputs() {
    let mut s = load(&format!(
        r#"
dimension = 3
[time]
step = 1e-3
steps = 50
[output]
every = 25
[[materials]]
name = "m"
density = {RHO:?}
[[laws]]
materials = ["m", "m"]
friction = 0.5
[[bodies]]
name = "table"
shape = "box"
material = "m"
half_extents = [0.5, 0.5, 0.05]
position = [0.0, 0.0, -0.05]
rotation = [0.0, 0.0, 0.3]
fixed = true
[[bodies]]
name = "ball"
shape = "sphere"
material = "m"
radius = {R:?}
position = [0.1, 0.2, {R:?}]
"#
    ));
    let dir = std::env::temp_dir().join(format!("nscdd-spheres-out-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let sum = nscdd::run::run(&mut s, &nscdd_spheres::registry(), &dir, |_, _| {}).unwrap();
    assert_eq!(sum.steps, 50);
    let w = &s.world;
    rel("weight on the box", w.reaction[0][2] / w.time.h, -w.bodies.mass[1] * G, 1e-9);
    let fin: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("final.json")).unwrap()).unwrap();
    assert_eq!(fin["dimension"], 3);
    assert_eq!(fin["bodies"][1]["kind"], "sphere");
    assert_eq!(fin["contacts"].as_array().unwrap().len(), 1);
    let hist = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    assert_eq!(hist.lines().count(), 51);
    assert!(hist.lines().next().unwrap().contains("ball_fz"));
    for f in [
        "bodies.pvd",
        "walls.pvd",
        "contacts.pvd",
        "vtk/bodies_000002.vtp",
        "vtk/walls_000002.vtp",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// NSCDD in 3D: a 6 × 6 × 4 stack of spheres on a floor, split 2 × 2 × 1 (and
/// 2 × 2 × 2, which puts bodies in up to 8 subdomains), agrees with one domain: the
/// contact forces of the stack are determinate (each vertical chain carries its
/// spheres' weight, the lateral contacts nothing), so the impulses of both solves
/// match to the solver's tolerance; the gluing leaves no jump between copies.
#[test]
fn nscdd_3d_pile_agrees_with_one_domain() {
    let scene = |dec: &str| {
        format!(
            r#"
dimension = 3
[time]
step = 1e-3
steps = 3
[solver]
# (1e-8 before LMGC90's non-updating check pass, which stops earlier)
tolerance = 1e-9
norm = "Quad"
max_sweeps = 100000
{dec}
[[materials]]
name = "m"
density = {RHO:?}
[[laws]]
materials = ["m", "m"]
friction = 0.4
[[bodies]]
name = "floor"
shape = "plane"
material = "m"
position = [0.0, 0.0, 0.0]
fixed = true
[[generate]]
kind = "sphere_lattice"
material = "m"
nx = 6
ny = 6
nz = 4
radius = {R:?}
origin = [{R:?}, {R:?}, {R:?}]
"#
        )
    };
    let mut one = load(&scene(""));
    steps(&mut one, 3);
    let m = one.world.bodies.mass[1];
    let h = one.world.time.h;
    for dec in [
        "[decomposition]\nnx = 2\nny = 2",
        "[decomposition]\nnx = 2\nny = 2\nnz = 2\nscheme = \"centralized\"",
    ] {
        let mut s = load(&scene(dec));
        let mut n = s.decomposition.as_ref().unwrap().solver3();
        let mut last = None;
        for _ in 0..3 {
            let r = n.step(&mut s.world).unwrap();
            assert!(r.solve.converged, "{dec}: {r:?}");
            last = Some(r);
        }
        let r = last.unwrap();
        let dec = dec.replace('\n', " ");
        println!(
            "{dec}: {} subdomains, {} interface bodies, max multiplicity {}, egluing {:.2e}, stages {}",
            r.subdomains, r.interface_bodies, r.max_multiplicity, r.egluing, r.stages
        );
        assert!(r.interface_bodies > 0 && r.subdomains >= 4);
        assert!(r.egluing_rel < 1e-8);
        let (a, b) = (&one.world.contacts, &s.world.contacts);
        assert_eq!(a.len(), b.len());
        let mut worst: f64 = 0.0;
        for k in 0..a.len() {
            assert_eq!(a.key[k], b.key[k]);
            for d in 0..3 {
                worst = worst.max((a.r[k][d] - b.r[k][d]).abs());
            }
        }
        // relative to the weight of one sphere over a step
        let rel = worst / (m * G * h);
        println!("{dec}: max |Δr| = {rel:.2e} × m g h");
        assert!(rel < 1e-6, "{dec}: impulses differ by {rel} m g h");
        // 2 threads: bitwise the same
        let mut t2 = load(&scene(&format!("{dec}\nthreads = 2").replace(' ', "\n").replace("\n=\n", " = ")));
        let mut n2 = t2.decomposition.as_ref().unwrap().solver3();
        for _ in 0..3 {
            n2.step(&mut t2.world).unwrap();
        }
        assert_eq!(t2.world.bodies.vel, s.world.bodies.vel, "{dec}: threads change the result");
        assert_eq!(t2.world.contacts.r, s.world.contacts.r);
        let v = s
            .world
            .bodies
            .vel
            .iter()
            .map(|v| v.iter().map(|x| x.abs()).fold(0.0, f64::max))
            .fold(0.0, f64::max);
        // at rest: within 1e-6 of the speed gravity adds in a step
        assert!(v < 1e-6 * G * h, "{dec}: the stack stays at rest, max |V| = {v}");
    }
}

/// A 3D run stopped at step 40 and continued from its final.json ends bitwise where
/// the uninterrupted run ends (spheres poured on a tilted box: rotations, friction,
/// warm-started impulses).
#[test]
fn restart_3d_continues_bitwise() {
    let scene = |steps: u64| {
        format!(
            r#"
dimension = 3
[time]
step = 1e-3
steps = {steps}
[output]
vtk = false
[[materials]]
name = "m"
density = {RHO:?}
[[laws]]
materials = ["m", "m"]
friction = 0.4
[[bodies]]
name = "table"
shape = "box"
material = "m"
half_extents = [0.3, 0.3, 0.02]
position = [0.0, 0.0, -0.02]
rotation = [0.1, 0.05, 0.0]
fixed = true
[[generate]]
kind = "sphere_packing"
material = "m"
count = 40
radius_min = 0.01
radius_max = 0.02
box = [-0.1, -0.1, 0.02, 0.1, 0.1, 0.15]
seed = 9
"#
        )
    };
    let tmp = |n: &str| std::env::temp_dir().join(format!("nscdd-restart3-{}-{n}", std::process::id()));
    let (a, b, c) = (tmp("whole"), tmp("first"), tmp("second"));
    let mut whole = load(&scene(80));
    nscdd::run::run(&mut whole, &nscdd_spheres::registry(), &a, |_, _| {}).unwrap();
    let mut first = load(&scene(40));
    nscdd::run::run(&mut first, &nscdd_spheres::registry(), &b, |_, _| {}).unwrap();
    let mut second = load(&scene(80));
    nscdd::scene::restart(&mut second.world, &b.join("final.json")).unwrap();
    nscdd::run::run(&mut second, &nscdd_spheres::registry(), &c, |_, _| {}).unwrap();
    let (x, y) = (
        std::fs::read_to_string(a.join("final.json")).unwrap(),
        std::fs::read_to_string(c.join("final.json")).unwrap(),
    );
    for (k, (p, q)) in x.lines().zip(y.lines()).enumerate() {
        assert_eq!(p, q, "line {} of final.json", k + 1);
    }
    assert!(whole.world.contacts.len() > 10);
    // a 2D state is refused, naming the key
    let mut third = load(&scene(80));
    let e = nscdd::scene::restart::restart_str(
        &mut third.world,
        "{\"dimension\": 2, \"step\": 1, \"time\": 0.001, \"bodies\": [], \"contacts\": []}",
        "s.json",
    )
    .unwrap_err();
    assert_eq!(e.key, "dimension", "{e}");
    for d in [a, b, c] {
        let _ = std::fs::remove_dir_all(d);
    }
}

/// The `compliant` law in 3D: a sphere resting on a plane sinks by m g / k, and
/// after an undamped bounce on it (no gravity, θ = ½) leaves at its incoming speed.
#[test]
fn compliant_sphere_sinks_by_its_weight_over_k_and_bounces_back() {
    let k = 1e6;
    let m = RHO * 4.0 / 3.0 * std::f64::consts::PI * R.powi(3);
    let text = |gravity: &str, damping: f64, z: f64| {
        format!(
            r#"
dimension = 3
{gravity}
[time]
step = 1e-4
theta = 0.5
steps = 100
[solver]
tolerance = 1e-12
max_sweeps = 10000
[[materials]]
name = "m"
density = {RHO:?}
[[laws]]
materials = ["m", "m"]
law = "compliant"
stiffness = {k:?}
damping = {damping:?}
friction = 0.5
[[bodies]]
shape = "plane"
material = "m"
position = [0.0, 0.0, 0.0]
fixed = true
[[bodies]]
shape = "sphere"
material = "m"
radius = {R:?}
position = [0.0, 0.0, {z:?}]
"#
        )
    };
    let mut s = load(&text("", (k * m).sqrt(), R));
    steps(&mut s, 5000);
    rel("gap at rest", s.world.bodies.pos[1][2] - R, -m * G / k, 1e-9);
    let mut s = load(&text("gravity = [0.0, 0.0, 0.0]", 0.0, R + 1e-3));
    let v = 0.1;
    s.world.bodies.vel[1] = [0.0, 0.0, -v, 0.0, 0.0, 0.0];
    steps(&mut s, 2000);
    // the 2D bounce's bound: O(ω h)
    let omega = (k / m).sqrt();
    rel("speed after", s.world.bodies.vel[1][2], v, omega * 1e-4);
}
