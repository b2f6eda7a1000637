//! A disk on a fixed incline (a wall for the block tests, a half-plane for the free
//! disk) rotated by α: outward normal n = (−sin α, cos α), downhill unit vector
//! d = (−cos α, −sin α) (which is also the contact tangent t = (−n_y, n_x)). Gravity (0, −g), disk of radius R, mass
//! m = ρ π R², inertia I = m R²/2, placed touching the plane (gap 0) at rest.
//!
//! Why the tolerances are tight: there is a single contact and its Delassus block is
//! diagonal (W_nn = 1/m; W_tt = 1/m for a block whose rotation is driven, 1/m + R²/I
//! = 3/m for a free disk; W_nt = 0 because the lever arm is along n). The local 2D
//! Coulomb solver enumerates the cases in closed form, so each step reproduces the
//! analytic impulses up to rounding: a relative 1e-9 leaves room for the rounding of
//! a few hundred accumulated steps (≈ 1e-13 observed) and nothing for a wrong law.

use crate::common::{assert_abs, assert_rel, disk_mass, scene, steps, G};
use nscdd::scene::Scene;

const R: f64 = 0.1;
const RHO: f64 = 1000.0;
const H: f64 = 1e-3;
/// Relative tolerance of the single-contact results (see the module docs).
const EXACT: f64 = 1e-9;

/// Thickness of the wall used as an incline.
const T: f64 = 0.02;

/// A disk touching the incline of angle `alpha` with friction `mu`; `block` drives
/// its rotation to ω = 0. The incline is a half-plane through the origin or, with
/// `wall`, a 4 m long wall of thickness T centred at the origin and rotated by α
/// (its top face is then the plane at T/2 along n): both detectors are exercised.
fn incline(alpha: f64, mu: f64, block: bool, wall: bool) -> Scene {
    scene(&incline_text(alpha, mu, block, wall))
}

/// The scene text of [`incline`].
fn incline_text(alpha: f64, mu: f64, block: bool, wall: bool) -> String {
    let (sa, ca) = alpha.sin_cos();
    let off = if wall { R + 0.5 * T } else { R };
    let pos = [-sa * off, ca * off];
    let drive = if block { "drive = { rot = { velocity = 0.0 } }" } else { "" };
    let support = if wall {
        format!("shape = \"wall\"\nlength = 4.0\nthickness = {T:?}")
    } else {
        "shape = \"halfplane\"".to_string()
    };
    format!(
        r#"
[time]
step = {H:?}
steps = 1000
[solver]
tolerance = 1e-8
[[materials]]
name = "m"
density = {RHO:?}
[[laws]]
materials = ["m", "m"]
friction = {mu:?}
[[bodies]]
name = "slope"
{support}
material = "m"
position = [0.0, 0.0]
rotation = {alpha:?}
fixed = true
[[bodies]]
name = "disk"
shape = "disk"
material = "m"
radius = {R:?}
position = [{:?}, {:?}]
{drive}
"#,
        pos[0], pos[1]
    )
}

fn downhill(alpha: f64) -> [f64; 2] {
    [-alpha.cos(), -alpha.sin()]
}

/// Velocity of the disk along the slope (downhill positive) and normal to it.
fn v_slope(s: &Scene, alpha: f64) -> (f64, f64) {
    let v = s.world.bodies.vel[1];
    let d = downhill(alpha);
    (v[0] * d[0] + v[1] * d[1], -alpha.sin() * v[0] + alpha.cos() * v[1])
}

/// Runs `n0` steps, then measures the downhill acceleration over `n1` more steps
/// (a finite difference of velocities: exact for constant acceleration).
fn acceleration(s: &mut Scene, alpha: f64, n0: usize, n1: usize) -> (f64, f64) {
    steps(s, n0);
    let (v0, w0) = (v_slope(s, alpha).0, s.world.bodies.vel[1][2]);
    steps(s, n1);
    let (v1, w1) = (v_slope(s, alpha).0, s.world.bodies.vel[1][2]);
    let dt = n1 as f64 * H;
    ((v1 - v0) / dt, (w1 - w0) / dt)
}

/// Block (rotation locked): sticks iff tan α ≤ μ. Just below the threshold
/// (tan α = 0.95 μ) it stays at rest and the contact carries, per step, the normal
/// impulse m g h cos α and the friction impulse m g h sin α (uphill: r_t < 0).
#[test]
fn block_sticks_below_tan_alpha_eq_mu() {
    let mu: f64 = 0.5;
    let alpha = (0.95 * mu).atan();
    let mut s = incline(alpha, mu, true, true);
    let x0 = s.world.bodies.pos[1];
    steps(&mut s, 200);
    let m = disk_mass(RHO, R);
    let b = &s.world.bodies;
    let moved = ((b.pos[1][0] - x0[0]).powi(2) + (b.pos[1][1] - x0[1]).powi(2)).sqrt();
    // at rest: the velocity is the sum of gravity and contact increments that cancel
    // exactly up to rounding (~1e-16 × g h per step)
    assert_abs("block speed at rest (m/s)", b.vel[1][0].hypot(b.vel[1][1]), 0.0, 1e-12);
    assert_abs("block displacement (m)", moved, 0.0, 1e-12);
    assert_eq!(s.world.contacts.len(), 1);
    let r = s.world.contacts.r[0];
    assert_rel("normal impulse r_n (N s)", r[0], m * G * H * alpha.cos(), EXACT);
    assert_rel("friction impulse r_t (N s)", r[1], -m * G * H * alpha.sin(), EXACT);
    // the reaction resultant on the block balances its weight over the step
    assert_rel("reaction on the block, y (N s)", s.world.reaction[1][1], m * G * H, EXACT);
}

/// Block just above the threshold (tan α = 1.05 μ): slides with
/// a = g (sin α − μ cos α), the friction impulse on the cone's edge μ r_n.
#[test]
fn block_slides_above_tan_alpha_eq_mu() {
    let mu: f64 = 0.5;
    let alpha = (1.05 * mu).atan();
    let mut s = incline(alpha, mu, true, true);
    let (a, _) = acceleration(&mut s, alpha, 50, 150);
    assert_rel("block acceleration (m/s²)", a, G * (alpha.sin() - mu * alpha.cos()), EXACT);
    let r = s.world.contacts.r[0];
    let m = disk_mass(RHO, R);
    assert_rel("normal impulse r_n (N s)", r[0], m * G * H * alpha.cos(), EXACT);
    assert_rel("friction impulse r_t = −μ r_n (N s)", r[1], -mu * r[0], EXACT);
    // stays on the plane: no normal velocity
    assert_abs("normal velocity (m/s)", v_slope(&s, alpha).1, 0.0, 1e-12);
    assert_eq!(s.world.bodies.vel[1][2], 0.0, "the block's rotation is driven to 0");
}

/// Free disk, μ = 1.05 tan α / 3 (just above the rolling threshold): rolls without
/// slipping, a = (2/3) g sin α, ω = v/R, and the friction impulse is
/// m g h sin α / 3 < μ r_n.
#[test]
fn disk_rolls_above_mu_eq_tan_alpha_over_3() {
    let alpha = 30f64.to_radians();
    let mu = 1.05 * alpha.tan() / 3.0;
    let mut s = incline(alpha, mu, false, false);
    let (a, alpha_rot) = acceleration(&mut s, alpha, 50, 150);
    assert_rel("rolling acceleration (m/s²)", a, 2.0 / 3.0 * G * alpha.sin(), EXACT);
    assert_rel("angular acceleration (rad/s²)", alpha_rot, a / R, EXACT);
    let (v, _) = v_slope(&s, alpha);
    assert_rel("ω = v/R (rad/s)", s.world.bodies.vel[1][2], v / R, EXACT);
    let m = disk_mass(RHO, R);
    let r = s.world.contacts.r[0];
    assert_rel("friction impulse (N s)", r[1], -m * G * H * alpha.sin() / 3.0, EXACT);
    assert!(r[1].abs() < mu * r[0], "rolling is sticking at the contact point");
}

/// Free disk, μ = 0.95 tan α / 3: slips, a = g (sin α − μ cos α), and the friction
/// torque μ m g cos α R gives ω̇ = 2 μ g cos α / R < a/R.
#[test]
fn disk_slips_below_mu_eq_tan_alpha_over_3() {
    let alpha = 30f64.to_radians();
    let mu = 0.95 * alpha.tan() / 3.0;
    let mut s = incline(alpha, mu, false, false);
    let (a, alpha_rot) = acceleration(&mut s, alpha, 50, 150);
    assert_rel("slipping acceleration (m/s²)", a, G * (alpha.sin() - mu * alpha.cos()), EXACT);
    assert_rel("angular acceleration (rad/s²)", alpha_rot, 2.0 * mu * G * alpha.cos() / R, EXACT);
    let (v, _) = v_slope(&s, alpha);
    let slip = v - R * s.world.bodies.vel[1][2];
    assert!(slip > 0.0, "the contact point slides downhill, slip velocity {slip}");
    let r = s.world.contacts.r[0];
    assert_rel("friction impulse r_t = −μ r_n (N s)", r[1], -mu * r[0], EXACT);
}

/// Anderson and Newton (`[solver] method`), and over-relaxed NLGS and Anderson
/// (`relaxation` 1.2 and 1.3), give the incline's answers too: the block sticking
/// below tan α = μ and sliding above it, the free disk rolling above μ = tan α / 3
/// and slipping below it (one contact: every method solves its problem exactly,
/// hence the same tolerance).
#[test]
fn every_method_gives_the_incline_answers() {
    let m = disk_mass(RHO, R);
    for (method, omega) in [("anderson", 1.0), ("newton", 1.0), ("nlgs", 1.2), ("anderson", 1.3)] {
        let with = |alpha: f64, mu: f64, block: bool| {
            let text = incline_text(alpha, mu, block, true);
            let solver = format!("tolerance = 1e-8\nmethod = \"{method}\"\nrelaxation = {omega:?}");
            scene(&text.replace("tolerance = 1e-8", &solver))
        };
        let method = format!("{method} ω = {omega}");
        let mu: f64 = 0.5;
        let alpha = (0.95 * mu).atan();
        let mut s = with(alpha, mu, true);
        steps(&mut s, 200);
        assert_abs(&format!("{method}: block speed at rest"), v_slope(&s, alpha).0, 0.0, 1e-12);
        assert_rel(
            &format!("{method}: friction r_t"),
            s.world.contacts.r[0][1],
            -m * G * H * alpha.sin(),
            EXACT,
        );
        let alpha = (1.05 * mu).atan();
        let mut s = with(alpha, mu, true);
        let (a, _) = acceleration(&mut s, alpha, 50, 150);
        assert_rel(&format!("{method}: sliding block"), a, G * (alpha.sin() - mu * alpha.cos()), EXACT);
        let alpha: f64 = 0.4;
        let mut s = with(alpha, 1.05 * alpha.tan() / 3.0, false);
        let (a, w) = acceleration(&mut s, alpha, 50, 150);
        assert_rel(&format!("{method}: rolling disk"), a, 2.0 / 3.0 * G * alpha.sin(), EXACT);
        assert_rel(&format!("{method}: rolling disk ω̇ R"), w * R, a, EXACT);
        let mu = 0.95 * alpha.tan() / 3.0;
        let mut s = with(alpha, mu, false);
        let (a, _) = acceleration(&mut s, alpha, 50, 150);
        assert_rel(&format!("{method}: slipping disk"), a, G * (alpha.sin() - mu * alpha.cos()), EXACT);
    }
}
