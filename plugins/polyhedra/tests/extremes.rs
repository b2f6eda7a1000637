//! Stability of polyhedra and mortar joints at the extremes (docs/EXTREMES.md,
//! "3D: polyhedra and mortar joints"): a mass ratio of 10⁶, μ = 0 and 10, steps
//! from 10⁻⁶ to 10⁻¹ s, a tall stack, a thin and a large block, each dry and bonded
//! (law `mohr_coulomb`) where the setting allows. Every case checks that no
//! position, orientation, velocity or impulse becomes NaN or infinite, that the
//! interpenetration stays under a stated bound, and that a step whose solve did not
//! meet the criterion says so (`converged = false`, counted here). Run with
//! `--nocapture` for the `[extremes-poly]` lines.
//!
//! Bounds (as for spheres, tests/tests/extremes3d.rs): an approach at speed v closes
//! at most h v (1 − θ) + max(0, h v − alert) beyond the contact in one step, and a
//! loaded contact may creep by the velocity error the solver leaves, allowed as
//! 10 % of g h per step.

use nscdd::scene::Scene3;
use nscdd::world::World3;
use nscdd_polyhedra::generate::box_points;

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

fn run(case: &str, text: &str) -> (World3, Figures) {
    let reg = nscdd_polyhedra::registry();
    let mut w = match Scene3::load_str(text, case, &reg) {
        Ok(s) => s.world,
        Err(e) => panic!("{case}: {e}"),
    };
    let mut f = Figures::default();
    for _ in 0..w.time.steps {
        let rep = w.step().unwrap_or_else(|d| panic!("{case}: {d}"));
        f.steps += 1;
        f.sweeps += rep.solve.sweeps as u64;
        f.unconverged += (!rep.solve.converged) as u64;
        assert!(rep.solve.residual.is_finite(), "{case}: non-finite residual at step {}", w.step);
        assert!(w.contacts.r.iter().flatten().all(|x| x.is_finite()), "{case}: non-finite impulse");
        let b = &w.bodies;
        assert!(
            b.pos
                .iter()
                .flatten()
                .chain(b.rot.iter().flatten())
                .chain(b.vel.iter().flatten())
                .all(|x| x.is_finite()),
            "{case}: non-finite body state at step {}",
            w.step
        );
        f.max_residual = f.max_residual.max(rep.solve.residual);
        f.contacts = f.contacts.max(rep.contacts);
        for &g in &w.contacts.gap {
            f.max_pen = f.max_pen.max(-g);
        }
    }
    println!(
        "[extremes-poly] {case}: {} steps, contacts ≤ {}, mean sweeps {:.1}, unconverged {}/{}, max interpenetration {:.3e} m, max residual {:.2e}",
        f.steps,
        f.contacts,
        f.sweeps as f64 / f.steps.max(1) as f64,
        f.unconverged,
        f.steps,
        f.max_pen,
        f.max_residual
    );
    (w, f)
}

/// A box polyhedron from `lo` to `hi` of material `mat`.
fn block(name: &str, mat: &str, lo: [f64; 3], hi: [f64; 3], fixed: bool) -> String {
    let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let v: Vec<String> = box_points(lo, hi)
        .iter()
        .map(|p| format!("[{:e}, {:e}, {:e}]", p[0] - c[0], p[1] - c[1], p[2] - c[2]))
        .collect();
    format!(
        "[[bodies]]\nname = \"{name}\"\nshape = \"polyhedron\"\nmaterial = \"{mat}\"\nposition = [{:e}, {:e}, {:e}]\nfixed = {fixed}\nvertices = [{}]\n",
        c[0],
        c[1],
        c[2],
        v.join(", ")
    )
}

/// A scene of stone (2000 kg/m³) and heavy (2·10⁹ kg/m³) blocks on a fixed floor
/// plane; `law` is the stone–stone and stone–heavy law's body (dry Coulomb or a
/// bonded `mohr_coulomb` joint).
fn scene(gravity: [f64; 3], h: f64, steps: u64, alert: f64, law: &str, solver: &str, bodies: &str) -> String {
    format!(
        r#"dimension = 3
gravity = [{:e}, {:e}, {:e}]
[time]
step = {h:e}
theta = 0.5
steps = {steps}
[solver]
{solver}
[detection]
alert = {alert:e}
[[materials]]
name = "stone"
density = 2000.0
[[materials]]
name = "heavy"
density = 2e9
[[laws]]
materials = ["stone", "stone"]
{law}
[[laws]]
materials = ["stone", "heavy"]
{law}
[[laws]]
materials = ["heavy", "heavy"]
friction = 0.5
[[bodies]]
name = "floor"
shape = "plane"
material = "stone"
position = [0.0, 0.0, 0.0]
fixed = true
{bodies}"#,
        gravity[0], gravity[1], gravity[2]
    )
}

const DRY: &str = "friction = 0.5";
/// A mortar joint: bonded at the first step where blocks touch.
const MORTAR: &str = "law = \"mohr_coulomb\"\nfriction = 0.6\ncohesion = 1e5\ntensile_strength = 5e4";

/// A stack of `n` bricks 0.2 × 0.1 × 0.05 m standing on the floor, of `mat`.
fn stack(n: usize, mat: &str) -> String {
    (0..n)
        .map(|k| {
            block(
                &format!("b{k}"),
                mat,
                [-0.1, -0.05, 0.05 * k as f64],
                [0.1, 0.05, 0.05 * (k + 1) as f64],
                false,
            )
        })
        .collect()
}

/// The impact and creep bound of the module docs.
fn bound(h: f64, v: f64, alert: f64, steps: u64) -> f64 {
    0.5 * h * v + (h * v - alert).max(0.0) + 0.1 * steps as f64 * G * h * h
}

/// A brick of 2·10⁹ kg/m³ on one of 2000 kg/m³, dry and bonded: the light brick
/// carries 10⁶ times its weight. NLGS stalls on such a pair (the run says so); the
/// heavy brick must not go through.
#[test]
fn mass_ratio_of_a_million() {
    for (name, law) in [("dry", DRY), ("mortar", MORTAR)] {
        let bodies = block("light", "stone", [-0.1, -0.05, 0.0], [0.1, 0.05, 0.05], false)
            + &block("heavy", "heavy", [-0.1, -0.05, 0.05], [0.1, 0.05, 0.1], false);
        let t = scene(
            [0.0, 0.0, -G],
            1e-3,
            200,
            2e-3,
            law,
            "tolerance = 1e-6\nmax_sweeps = 20000",
            &bodies,
        );
        let (w, f) = run(&format!("mass ratio 1e6, {name}"), &t);
        // NLGS stalls on a 10⁶ mass ratio (as for disks and spheres): the light brick
        // does not hold the whole weight at every step, and the run says so
        assert!(
            f.unconverged > 0 || f.max_residual > 100.0 * 1e-6,
            "{name}: the stall must be reported"
        );
        // bounded: the heavy brick sinks by less than 2 % of a free fall over the run
        // (0.2 s: 0.196 m), the overlap stays under 10 % of the light brick's height
        let sank = 0.075 - w.bodies.pos[2][2];
        println!("[extremes-poly] mass ratio 1e6, {name}: the heavy brick sank {sank:.3e} m");
        assert!(sank < 0.02 * 0.5 * G * 0.2 * 0.2, "{name}: the heavy brick sank {sank} m");
        assert!(f.max_pen < 5e-3, "{name}: interpenetration {} m", f.max_pen);
    }
}

/// μ = 0 and μ = 10, dry, on a floor tilted by α = 30° (gravity tilted): with μ = 0
/// the brick slides as x = ½ g sin α t² (exact to round-off after the first step),
/// with μ = 10 it stays; a bonded brick with μ = 10 stays too.
#[test]
fn friction_zero_and_ten() {
    let alpha = 30f64.to_radians();
    let g = [G * alpha.sin(), 0.0, -G * alpha.cos()];
    let brick = block("brick", "stone", [-0.1, -0.05, 0.0], [0.1, 0.05, 0.05], false);
    let (h, steps) = (1e-3, 300u64);
    let (w, f) = run("μ = 0, 30° incline", &scene(g, h, steps, 2e-3, "friction = 0.0", "", &brick));
    let t = h * steps as f64;
    let x = w.bodies.pos[1][0];
    let slide = 0.5 * G * alpha.sin() * t * t;
    assert!((x - slide).abs() < 0.01 * slide, "μ = 0: slid {x} m, ½ g sin α t² = {slide} m");
    assert!(f.max_pen <= bound(h, 0.0, 2e-3, steps));
    for (name, law) in [
        ("μ = 10, 30° incline", "friction = 10.0".to_string()),
        (
            "mortar μ = 10, 30° incline",
            "law = \"mohr_coulomb\"\nfriction = 10.0\ncohesion = 1e5".into(),
        ),
    ] {
        let (w, f) = run(name, &scene(g, h, steps, 2e-3, &law, "", &brick));
        let x = w.bodies.pos[1][0];
        assert!(x.abs() < 1e-9, "{name}: moved {x} m");
        assert!(f.max_pen <= bound(h, 0.0, 2e-3, steps));
    }
}

/// Steps from 10⁻⁶ to 10⁻¹ s: a stack of 5 bricks (dry and bonded) hit by a brick
/// dropped from 10 cm above it (alert ≥ h v_max for the large steps).
#[test]
fn time_steps_from_1e_6_to_1e_1() {
    for (h, steps) in [(1e-6, 300u64), (1e-4, 300), (1e-2, 100), (1e-1, 30)] {
        for (name, law) in [("dry", DRY), ("mortar", MORTAR)] {
            let v = (2.0 * G * 0.1f64).sqrt() + G * h;
            let alert = (h * v).max(1e-3);
            let bodies = stack(5, "stone") + &block("dropped", "stone", [-0.05, -0.05, 0.35], [0.05, 0.05, 0.4], false);
            let (_, f) = run(
                &format!("h = {h:e}, {name}"),
                &scene([0.0, 0.0, -G], h, steps, alert, law, "", &bodies),
            );
            let b = bound(h, v, alert, steps);
            assert!(f.max_pen <= b.max(1e-9), "h = {h}, {name}: interpenetration {} > {b}", f.max_pen);
        }
    }
}

/// A stack of 100 bricks (5 m), dry and bonded: after 100 steps the floor carries
/// the stack's weight to the solver's accuracy (NLGS on a long chain: the residual
/// says how far).
#[test]
fn tall_stack_of_100_bricks() {
    let n = 100;
    let weight = n as f64 * 2000.0 * 0.2 * 0.1 * 0.05 * G;
    for (name, law) in [("dry", DRY), ("mortar", MORTAR)] {
        let (h, steps) = (1e-3, 100u64);
        let t = scene([0.0, 0.0, -G], h, steps, 1e-3, law, "max_sweeps = 5000", &stack(n, "stone"));
        let (w, f) = run(&format!("stack of {n}, {name}"), &t);
        assert!(f.max_pen <= bound(h, 0.0, 1e-3, steps), "{name}: {}", f.max_pen);
        // the floor's reaction: the normal impulses of the contacts with body 0
        let mut rn = 0.0;
        for a in 0..w.contacts.len() {
            if w.contacts.bodies[a].contains(&0) {
                rn += w.contacts.r[a][0];
            }
        }
        let ratio = rn / h / weight;
        println!("[extremes-poly] stack of {n}, {name}: floor reaction / weight = {ratio:.4}");
        assert!((ratio - 1.0).abs() < 0.1, "{name}: the floor carries {ratio} × the weight");
    }
}

/// A thin plate (1 m × 1 m × 1 mm) on the floor with a brick dropped on it, and a
/// large block (10 × 10 × 2 m, 400 t) with a brick on top; dry and bonded.
#[test]
fn thin_and_large_blocks() {
    for (name, law) in [("dry", DRY), ("mortar", MORTAR)] {
        let (h, steps) = (1e-3, 200u64);
        let v = (2.0 * G * 0.05f64).sqrt() + G * h;
        let thin = block("plate", "stone", [-0.5, -0.5, 0.0], [0.5, 0.5, 0.001], false)
            + &block("brick", "stone", [-0.1, -0.05, 0.051], [0.1, 0.05, 0.101], false);
        let (w, f) = run(
            &format!("thin plate, {name}"),
            &scene([0.0, 0.0, -G], h, steps, 1e-3, law, "", &thin),
        );
        assert!(f.max_pen <= bound(h, v, 1e-3, steps), "{name}: {}", f.max_pen);
        assert!(w.bodies.pos[1][2] > 0.0, "{name}: the plate went through the floor");
        let large = block("large", "stone", [-5.0, -5.0, 0.0], [5.0, 5.0, 2.0], false)
            + &block("brick", "stone", [-0.1, -0.05, 2.0], [0.1, 0.05, 2.05], false);
        let (w, f) = run(
            &format!("large block, {name}"),
            &scene([0.0, 0.0, -G], h, steps, 1e-3, law, "", &large),
        );
        assert!(f.max_pen <= bound(h, 0.0, 1e-3, steps), "{name}: {}", f.max_pen);
        assert!((w.bodies.pos[1][2] - 1.0).abs() < 1e-3, "{name}: the large block moved");
    }
}
