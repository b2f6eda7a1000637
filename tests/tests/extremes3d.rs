//! Stability of the 3D engine at the extremes (docs/EXTREMES.md, "3D"): spheres
//! with a mass ratio of 10⁶, μ = 10, a column of 200 spheres, radii spread 1:50, and
//! steps from 10⁻⁶ to 10⁻¹ s. Every case checks that no position, velocity or
//! impulse becomes NaN or infinite, that the interpenetration stays under a stated
//! bound, and that a step whose solve did not meet the criterion says so (its report
//! is `converged = false`, counted here). Run with `--nocapture` for the
//! `[extremes3d]` lines.
//!
//! Bounds: an approach at speed v closes at most h v (1 − θ) + max(0, h v − alert)
//! beyond the contact in one step (the impact law acts on velocities, and a pair is
//! only seen within the alert distance); a loaded contact may creep by the velocity
//! error the solver leaves, allowed as 10 % of g h per step (as in 2D).

use nscdd::scene::Scene3;

const G: f64 = 9.81;

#[derive(Debug, Default)]
struct Figures {
    steps: u64,
    unconverged: u64,
    max_pen: f64,
    max_residual: f64,
    sweeps: u64,
    contacts: usize,
}

fn run(case: &str, text: &str) -> (Scene3, Figures) {
    let reg = nscdd_spheres::registry();
    let mut s = nscdd::scene::Scene3::load_str(text, case, &reg).unwrap_or_else(|e| panic!("{case}: {e}"));
    let mut f = Figures::default();
    for _ in 0..s.world.time.steps {
        let rep = s.world.step().unwrap_or_else(|d| panic!("{case}: {d}"));
        let w = &s.world;
        f.steps += 1;
        f.sweeps += rep.solve.sweeps as u64;
        f.unconverged += (!rep.solve.converged) as u64;
        assert!(rep.solve.residual.is_finite(), "{case}: non-finite residual at step {}", w.step);
        assert!(w.contacts.r.iter().flatten().all(|x| x.is_finite()), "{case}: non-finite impulse");
        assert!(
            w.bodies.rot.iter().flatten().all(|x| x.is_finite()),
            "{case}: non-finite orientation"
        );
        f.max_residual = f.max_residual.max(rep.solve.residual);
        f.contacts = f.contacts.max(rep.contacts);
        for &g in &w.contacts.gap {
            f.max_pen = f.max_pen.max(-g);
        }
    }
    println!(
        "[extremes3d] {case}: {} steps, contacts ≤ {}, mean sweeps {:.1}, unconverged {}/{}, max interpenetration {:.3e} m, max residual {:.2e}",
        f.steps,
        f.contacts,
        f.sweeps as f64 / f.steps.max(1) as f64,
        f.unconverged,
        f.steps,
        f.max_pen,
        f.max_residual
    );
    (s, f)
}

fn header(h: f64, steps: u64, mu: f64, extra_solver: &str) -> String {
    format!(
        r#"dimension = 3
[time]
step = {h:e}
steps = {steps}
[solver]
{extra_solver}
[[materials]]
name = "grain"
density = 1000.0
[[materials]]
name = "heavy"
density = 1e9
[[laws]]
materials = ["grain", "grain"]
friction = {mu:?}
[[laws]]
materials = ["grain", "heavy"]
friction = {mu:?}
[[bodies]]
name = "floor"
shape = "plane"
material = "grain"
position = [0.0, 0.0, 0.0]
fixed = true
"#
    )
}

fn sphere(name: &str, mat: &str, x: [f64; 3], r: f64) -> String {
    format!("[[bodies]]\nname = \"{name}\"\nshape = \"sphere\"\nmaterial = \"{mat}\"\nradius = {r:?}\nposition = {x:?}\n")
}

/// A sphere 10⁶ times heavier than the three light spheres it rests on.
#[test]
fn heavy_sphere_on_light_ones() {
    let r = 0.01;
    // three light spheres touching in a triangle, the heavy one in their dip
    let d = 2.0 * r / 3f64.sqrt();
    let mut t = header(1e-3, 200, 0.5, "tolerance = 1e-6\nmax_sweeps = 20000");
    for k in 0..3 {
        let a = k as f64 * std::f64::consts::TAU / 3.0;
        t += &sphere(&format!("l{k}"), "grain", [d * a.cos(), d * a.sin(), r], r);
    }
    let zt = r + (4.0 * r * r - d * d).sqrt();
    t += &sphere("top", "heavy", [0.0, 0.0, zt], r);
    let (s, f) = run("heavy 1e6", &t);
    let w = &s.world;
    let top = w.names.iter().position(|n| n.as_deref() == Some("top")).unwrap();
    let sink = zt - w.bodies.pos[top][2];
    println!("[extremes3d] heavy sphere sank by {sink:.3e} m in {} steps", f.steps);
    // NLGS stalls on a 10⁶ mass ratio (as in 2D): the light spheres do not hold the
    // whole weight at every step, and the run says so
    assert!(f.unconverged > 0 || f.max_residual > 100.0 * 1e-6, "the stall must be reported");
    // bounded: the heavy sphere sinks by less than 1 % of a free fall over the run
    let t = f.steps as f64 * 1e-3;
    assert!(sink < 0.01 * 0.5 * G * t * t, "sank {sink} m");
    assert!(f.max_pen < 0.05 * r, "interpenetration {} m", f.max_pen);
}

/// μ = 10: a locked sphere on a 60° incline sticks; a pile of spheres stays bounded.
#[test]
fn friction_ten() {
    let alpha = 60f64.to_radians();
    let r = 0.02;
    let t = format!(
        "{}{}drive = {{ rx = {{ velocity = 0.0 }}, ry = {{ velocity = 0.0 }}, rz = {{ velocity = 0.0 }} }}\n",
        header(1e-3, 300, 10.0, "tolerance = 1e-8").replace("rotation", "rotation").replace(
            "position = [0.0, 0.0, 0.0]\nfixed = true",
            &format!("position = [0.0, 0.0, 0.0]\nrotation = [0.0, {alpha:?}, 0.0]\nfixed = true")
        ),
        sphere("ball", "grain", [alpha.sin() * r, 0.0, alpha.cos() * r], r)
    );
    let (s, f) = run("mu 10 incline", &t);
    let v = s.world.bodies.vel[1];
    assert!(v.iter().all(|x| x.abs() < 1e-12), "μ = 10 holds the sphere: V = {v:?}");
    assert!(f.max_pen < 1e-9);
    // a pile with μ = 10 poured into a box of planes
    let mut t = header(1e-3, 400, 10.0, "");
    for (name, pos, rot) in [
        ("x0", [0.0, 0.0, 0.0], [0.0, 1.5707963267948966, 0.0]),
        ("x1", [0.2, 0.0, 0.0], [0.0, -1.5707963267948966, 0.0]),
        ("y0", [0.0, 0.0, 0.0], [-1.5707963267948966, 0.0, 0.0]),
        ("y1", [0.0, 0.2, 0.0], [1.5707963267948966, 0.0, 0.0]),
    ] {
        t += &format!("[[bodies]]\nname = \"{name}\"\nshape = \"plane\"\nmaterial = \"grain\"\nposition = {pos:?}\nrotation = {rot:?}\nfixed = true\n");
    }
    t += "[[generate]]\nkind = \"sphere_packing\"\nmaterial = \"grain\"\ncount = 300\nradius_min = 0.008\nradius_max = 0.012\nbox = [0.0, 0.0, 0.0, 0.2, 0.2, 0.3]\nseed = 3\n";
    let (_, f) = run("mu 10 pile", &t);
    // impacts at up to v = g t_fall ≈ 2.4 m/s with h = 1 ms, θ = ½, alert 1 mm
    let v = (2.0 * G * 0.3f64).sqrt();
    let bound = 0.5 * 1e-3 * v + (1e-3 * v - 1e-3f64).max(0.0) + 0.1 * 400.0 * 1e-3 * G * 1e-3;
    assert!(f.max_pen <= bound, "interpenetration {} > {bound}", f.max_pen);
}

/// A column of 200 spheres on a floor: finite, bounded creep, stalls reported.
#[test]
fn column_of_200_spheres() {
    let n = 200;
    let r = 0.01;
    let t = header(1e-3, 100, 0.3, "max_sweeps = 5000")
        + &format!(
            "[[generate]]\nkind = \"sphere_lattice\"\nmaterial = \"grain\"\nnx = 1\nnz = {n}\nradius = {r:?}\norigin = [0.0, 0.0, {r:?}]\n"
        );
    let (s, f) = run("column 200", &t);
    let w = &s.world;
    let m = w.bodies.mass[1];
    // the bottom contact against n m g
    let bottom = (0..w.contacts.len()).find(|&a| w.contacts.bodies[a].contains(&0)).unwrap();
    let ratio = w.contacts.r[bottom][0] / w.time.h / (n as f64 * m * G);
    println!("[extremes3d] column of {n}: bottom contact carries {:.3} of the weight", ratio);
    let bound = 0.1 * f.steps as f64 * 1e-3 * G * 1e-3;
    assert!(f.max_pen <= bound, "interpenetration {} > {bound}", f.max_pen);
    assert!(ratio > 0.0 && ratio.is_finite());
}

/// Radii spread 1:50: five spheres of 5 cm and 300 of 1 mm poured together.
#[test]
fn radii_spread_1_to_50() {
    let mut t = header(2e-4, 1500, 0.3, "") + "[detection]\nalert = 5e-4\n";
    for (name, pos, rot) in [
        ("x0", [0.0, 0.0, 0.0], [0.0, 1.5707963267948966, 0.0]),
        ("x1", [0.3, 0.0, 0.0], [0.0, -1.5707963267948966, 0.0]),
        ("y0", [0.0, 0.0, 0.0], [-1.5707963267948966, 0.0, 0.0]),
        ("y1", [0.0, 0.3, 0.0], [1.5707963267948966, 0.0, 0.0]),
    ] {
        t += &format!("[[bodies]]\nname = \"{name}\"\nshape = \"plane\"\nmaterial = \"grain\"\nposition = {pos:?}\nrotation = {rot:?}\nfixed = true\n");
    }
    t += "[[generate]]\nkind = \"sphere_packing\"\nmaterial = \"grain\"\ncount = 5\nradius_min = 0.05\nbox = [0.0, 0.0, 0.0, 0.3, 0.3, 0.12]\nseed = 1\n";
    t += "[[generate]]\nkind = \"sphere_packing\"\nmaterial = \"grain\"\ncount = 300\nradius_min = 0.001\nbox = [0.0, 0.0, 0.13, 0.3, 0.3, 0.2]\nseed = 2\n";
    let (_, f) = run("radii 1:50", &t);
    let v = (2.0 * G * 0.2f64).sqrt();
    let bound = 0.5 * 2e-4 * v + (2e-4 * v - 5e-4f64).max(0.0) + 0.1 * 1500.0 * 2e-4 * G * 2e-4;
    assert!(f.max_pen <= bound, "interpenetration {} > {bound}", f.max_pen);
}

/// Steps from 10⁻⁶ to 10⁻¹ s: a resting cubic stack of 27 spheres hit by four
/// spheres dropped from 15 cm (alert ≥ h v_max for the large steps).
#[test]
fn time_steps_from_1e_6_to_1e_1() {
    for (h, steps) in [(1e-6, 300u64), (1e-4, 300), (1e-2, 100), (1e-1, 30)] {
        let v = (2.0 * G * 0.2f64).sqrt() + G * h;
        let alert = (h * v).max(1e-3);
        let t = header(h, steps, 0.3, "")
            + &format!("[detection]\nalert = {alert:e}\n")
            + "[[generate]]\nkind = \"sphere_lattice\"\nmaterial = \"grain\"\nnx = 3\nny = 3\nnz = 3\nradius = 0.01\norigin = [0.0, 0.0, 0.01]\n"
            + "[[generate]]\nkind = \"sphere_lattice\"\nmaterial = \"grain\"\nnx = 2\nny = 2\nnz = 1\nradius = 0.01\nspacing = 0.02\norigin = [0.01, 0.01, 0.2]\n";
        let (_, f) = run(&format!("h = {h:e}"), &t);
        let bound = 0.5 * h * v + (h * v - alert).max(0.0) + 0.1 * steps as f64 * h * G * h;
        assert!(f.max_pen <= bound.max(1e-9), "h = {h}: interpenetration {} > {bound}", f.max_pen);
    }
}
