//! The `compliant` law (a normal spring k and dashpot d, solved implicitly as a
//! normal compliance): against the analytic answers of a mass on a spring.
//!
//! - a disk resting on a floor sinks by m g / k;
//! - a disk thrown at a fixed wall (no gravity, d = 0, θ = ½) stays in contact for
//!   half a period π √(m/k), sinks at most v/ω and leaves at its incoming speed;
//! - with a dashpot of damping ratio ζ = d / (2 √(k m)) it leaves at
//!   e = exp(−ζπ/√(1 − ζ²)) times its incoming speed;
//! - a chain of disks carries a compression front at the lattice's long-wave speed
//!   c = d √(k/m) (d the spacing).

use crate::common::{assert_rel, disk_mass, scene, step, steps, G};

const R: f64 = 0.05;
const RHO: f64 = 1000.0;
const K: f64 = 1e5;

fn header(gravity: bool, h: f64, theta: f64, damping: f64) -> String {
    let g = if gravity { "" } else { "gravity = [0.0, 0.0]\n" };
    format!(
        r#"{g}
[time]
step = {h:?}
theta = {theta:?}
steps = 100
[solver]
tolerance = 1e-12
max_sweeps = 100000
[[materials]]
name = "m"
density = {RHO:?}
[[laws]]
materials = ["m", "m"]
law = "compliant"
stiffness = {K:?}
damping = {damping:?}
friction = 0.3
"#
    )
}

const FLOOR: &str = r#"
[[bodies]]
shape = "wall"
material = "m"
position = [0.0, -0.01]
length = 1.0
thickness = 0.02
fixed = true
"#;

fn disk(x: f64, y: f64, vx: f64) -> String {
    format!("[[bodies]]\nshape = \"disk\"\nmaterial = \"m\"\nradius = {R:?}\nposition = [{x:?}, {y:?}]\nvelocity = [{vx:?}, 0.0, 0.0]\n")
}

#[test]
fn a_resting_disk_sinks_by_its_weight_over_k() {
    let m = disk_mass(RHO, R);
    // half the critical damping: settled to 1e-20 of the first sway after 1 s
    let d = (K * m).sqrt();
    let mut s = scene(&(header(true, 1e-3, 0.5, d) + FLOOR + &disk(0.0, R, 0.0)));
    steps(&mut s, 1000);
    let gap = s.world.bodies.pos[1][1] - R;
    // at rest the spring carries the weight: k (−g) = m g, whatever h and θ
    assert_rel("gap at rest", gap, -m * G / K, 1e-9);
    assert!(s.world.bodies.vel[1][1].abs() < 1e-12);
}

/// A disk at speed v towards a fixed wall at gap g0, no gravity: (time in contact,
/// deepest gap, speed after), from the steps where its contact impulse is > 0.
fn bounce(v: f64, h: f64, damping: f64) -> (f64, f64, f64) {
    let g0 = 2e-3;
    let mut s = scene(&(header(false, h, 0.5, damping) + FLOOR + &disk(0.0, R + g0, 0.0)));
    s.world.bodies.vel[1] = [0.0, -v, 0.0];
    let (mut touching, mut deepest) = (0usize, f64::MAX);
    for _ in 0..2000 {
        step(&mut s);
        let c = &s.world.contacts;
        if (0..c.len()).any(|a| c.r[a][0] > 0.0) {
            touching += 1;
        }
        deepest = deepest.min(s.world.bodies.pos[1][1] - R);
    }
    (touching as f64 * h, deepest, s.world.bodies.vel[1][1])
}

#[test]
fn an_undamped_bounce_lasts_half_a_period_and_keeps_the_speed() {
    let m = disk_mass(RHO, R);
    let omega = (K / m).sqrt();
    let v = 0.1;
    // ω h = 0.011: 285 steps in contact
    let h = 1e-4;
    let (t, deepest, v_after) = bounce(v, h, 0.0);
    // the contact time is counted in whole steps: ± 1 step
    assert_rel("time in contact", t, std::f64::consts::PI / omega, h * omega / std::f64::consts::PI);
    // the midpoint rule keeps the spring's energy: the deepest gap −v/ω and the
    // speed after, up to the steps where the contact opens and closes (their
    // impulses lag the θ-point by at most a step: O(ω h))
    assert_rel("deepest gap", deepest, -v / omega, omega * h);
    assert_rel("speed after", v_after, v, omega * h);
}

#[test]
fn a_damped_bounce_leaves_at_the_restitution_of_its_damping_ratio() {
    let m = disk_mass(RHO, R);
    let omega = (K / m).sqrt();
    let zeta: f64 = 0.1;
    let d = 2.0 * zeta * (K * m).sqrt();
    let h = 1e-4;
    let (_, _, v_after) = bounce(0.1, h, d);
    let e = (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
    // the same O(ω h) as the undamped bounce (measured 2e-4 for ζ = 0.1: the
    // dashpot's cut where k g + d u would pull, which the analytic e ignores,
    // changes the speed after by less)
    assert_rel("restitution", v_after / 0.1, e, omega * h);
}

#[test]
fn a_chain_of_disks_carries_a_front_at_the_lattice_wave_speed() {
    let n = 60;
    let m = disk_mass(RHO, R);
    let c = 2.0 * R * (K / m).sqrt();
    // a slow push on the first disk for the whole run: a step front
    let v = 1e-3;
    let h = 2e-4;
    let mut text = header(false, h, 0.5, 0.0);
    for k in 0..n {
        text += &disk(2.0 * R * k as f64, 0.0, 0.0);
        if k == 0 {
            text += &format!("drive.x = {{ velocity = {v:?} }}\ndrive.y = {{ velocity = 0.0 }}\n");
        }
    }
    let mut s = scene(&text);
    let (mut arrived, far) = (None, 50usize);
    // c = 11.3 m/s: 0.44 s to disk 50
    for k in 0..3000 {
        step(&mut s);
        if arrived.is_none() && s.world.bodies.vel[far][0] >= 0.5 * v {
            arrived = Some((k + 1) as f64 * h);
        }
    }
    let t = arrived.expect("the front reached disk 50");
    // the front of a step in a chain spreads as t^(1/3) around x = c t: its
    // half-height passes x at t = x/c up to that spread (Airy front: a few
    // spacings at 50 spacings), ± 10 %
    assert_rel("front's arrival", t, far as f64 * 2.0 * R / c, 0.1);
}

#[test]
fn every_solver_takes_the_compliance() {
    let m = disk_mass(RHO, R);
    let d = (K * m).sqrt();
    for method in ["anderson", "newton"] {
        let text = header(true, 1e-3, 0.5, d).replace("[solver]", &format!("[solver]\nmethod = \"{method}\""));
        // two disks in a column: the lower contact carries 2 m g
        let mut s = scene(&(text + FLOOR + &disk(0.0, R, 0.0) + &disk(0.0, 3.0 * R, 0.0)));
        steps(&mut s, 1000);
        let p = &s.world.bodies.pos;
        assert_rel(&format!("{method}: lower gap"), p[1][1] - R, -2.0 * m * G / K, 1e-8);
        assert_rel(&format!("{method}: upper gap"), p[2][1] - p[1][1] - 2.0 * R, -m * G / K, 1e-8);
    }
}

#[test]
fn bad_parameters_are_refused_naming_the_key() {
    let reg = nscdd_rigid_disks::registry();
    let base = header(true, 1e-3, 0.5, 0.0) + FLOOR + &disk(0.0, R, 0.0);
    for (from, to, key) in [
        ("stiffness = 100000.0", "stiffness = 0.0", "laws[0].stiffness"),
        ("stiffness = 100000.0", "", "laws[0].stiffness"),
        ("damping = 0.0", "damping = -1.0", "laws[0].damping"),
        ("friction = 0.3", "friction = -0.3", "laws[0].friction"),
        ("friction = 0.3", "restitution = 0.5", "laws[0].restitution"),
    ] {
        assert!(base.contains(from), "{from}");
        let err = nscdd::scene::load_str(&base.replace(from, to), "c.toml", &reg)
            .err()
            .expect("refused");
        assert_eq!(err.key, key, "{err}");
    }
}
