//! Impacts: Newton's cradle (Moreau's simultaneous impact law) and a ball bouncing
//! on a fixed floor with Newton restitution.

use crate::common::{assert_abs, assert_rel, disk_mass, lcp_enumerate, scene, step, G};
use nscdd::scene::Scene;

const R: f64 = 0.05;
const RHO: f64 = 1000.0;

/// N touching equal balls on the x axis (gravity off, μ = 0, e = 1), the first one
/// moving at v towards the others.
fn cradle(n: usize, v: f64, ordering: &str) -> Scene {
    let mut text = format!(
        r#"
gravity = [0.0, 0.0]
[time]
step = 1e-3
steps = 100
[solver]
tolerance = 1e-10
max_sweeps = 100000
ordering = "{ordering}"
seed = 3
[[materials]]
name = "steel"
density = {RHO:?}
[[laws]]
materials = ["steel", "steel"]
law = "frictionless"
restitution = 1.0
"#
    );
    for k in 0..n {
        let vx = if k == 0 { v } else { 0.0 };
        text += &format!(
            "[[bodies]]\nshape = \"disk\"\nmaterial = \"steel\"\nradius = {R:?}\nposition = [{:?}, 0.0]\nvelocity = [{vx:?}, 0.0, 0.0]\n",
            2.0 * R * k as f64
        );
    }
    scene(&text)
}

/// Moreau's impact law for the chain, solved densely: contact k joins balls k and
/// k+1 with u_k = v_{k+1} − v_k (the engine's frame: n from k+1 to k), so
/// u = Hᵀ V with H[k][k] = −1, H[k+1][k] = 1, W = Hᵀ M⁻¹ H, and the law
/// u⁺ ≥ ū = −e min(u⁻, 0) ⊥ r ≥ 0 is the LCP W r + (Hᵀ V⁻ − ū) ≥ 0 ⊥ r ≥ 0.
/// Returns V⁺ = V⁻ + M⁻¹ H r.
fn moreau_chain(v0: &[f64], m: f64, e: f64) -> Vec<f64> {
    let n = v0.len();
    let nc = n - 1;
    let hmat = |b: usize, c: usize| {
        if b == c {
            -1.0
        } else if b == c + 1 {
            1.0
        } else {
            0.0
        }
    };
    let w: Vec<Vec<f64>> = (0..nc)
        .map(|a| (0..nc).map(|c| (0..n).map(|b| hmat(b, a) * hmat(b, c) / m).sum()).collect())
        .collect();
    let q: Vec<f64> = (0..nc)
        .map(|c| {
            let u: f64 = (0..n).map(|b| hmat(b, c) * v0[b]).sum();
            u + e * u.min(0.0)
        })
        .collect();
    let r = lcp_enumerate(&w, &q);
    (0..n)
        .map(|b| v0[b] + (0..nc).map(|c| hmat(b, c) * r[c]).sum::<f64>() / m)
        .collect()
}

/// Newton's cradle with N = 3 and N = 5 balls: after the impact step the velocities
/// are Moreau's solution, (−(N−2)/N, 2/N, …, 2/N) v (for N = 3: (−1/3, 2/3, 2/3) v),
/// the same for the orderings stored, reversed and shuffled; momentum m v and
/// kinetic energy ½ m v² are kept (e = 1 and all contacts active).
///
/// Tolerance: W is positive definite (the chain of N bodies has N − 1 independent
/// contacts), so the LCP has one solution and the orderings only change how NLGS
/// reaches it. Solved to tol = 1e-10, GS on this chain contracts by
/// ρ = cos²(π/N) ≤ 0.66 (N = 5) per sweep, so the impulses are within ~tol/(1 − ρ)
/// ≈ 3e-10 relative: we assert 1e-8 relative to v on every velocity. Momentum is
/// kept exactly by every NLGS update (equal and opposite impulses): 1e-12.
#[test]
fn newtons_cradle_is_moreau_simultaneous_impact() {
    let v = 1.0;
    for n in [3usize, 5] {
        let m = disk_mass(RHO, R);
        let mut v0 = vec![0.0; n];
        v0[0] = v;
        let expected = moreau_chain(&v0, m, 1.0);
        // the closed form: all contacts active, end balls' relative velocity v
        let nf = n as f64;
        assert_abs("dense LCP vs closed form, first ball", expected[0], -(nf - 2.0) / nf * v, 1e-12);
        for x in &expected[1..] {
            assert_abs("dense LCP vs closed form, other balls", *x, 2.0 / nf * v, 1e-12);
        }
        for ordering in ["stored", "reversed", "shuffled"] {
            let mut s = cradle(n, v, ordering);
            let rep = step(&mut s);
            println!(
                "N = {n}, {ordering}: impact step: {} sweeps, natural-map residual {:.2e}",
                rep.solve.sweeps, rep.solve.residual
            );
            assert!(rep.solve.residual < 1e-9, "impact step residual {:e}", rep.solve.residual);
            for _ in 0..5 {
                // separated or at equal velocities: nothing changes; the touching
                // pairs' impulses are round-off, which must not stall the solver
                let rep = step(&mut s);
                assert!(
                    rep.solve.sweeps <= 100 && rep.solve.residual < 1e-9,
                    "after the impact: {:?}",
                    rep.solve
                );
            }
            let b = &s.world.bodies;
            for k in 0..n {
                assert_abs(
                    &format!("N = {n}, {ordering}: v_x of ball {k} (m/s)"),
                    b.vel[k][0],
                    expected[k],
                    1e-8 * v,
                );
                assert_abs("v_y", b.vel[k][1], 0.0, 1e-15);
            }
            let p: f64 = b.vel.iter().map(|x| m * x[0]).sum();
            let (ek, _) = s.world.energies();
            assert_rel(&format!("N = {n}, {ordering}: momentum (kg m/s)"), p, m * v, 1e-12);
            assert_rel(&format!("N = {n}, {ordering}: kinetic energy (J)"), ek, 0.5 * m * v * v, 1e-8);
        }
    }
}

/// A ball of radius R dropped from rest with its lowest point h0 above a fixed
/// floor (half-plane y = 0).
fn bouncing(h0: f64, e: f64, h: f64, theta: f64) -> Scene {
    scene(&format!(
        r#"
[time]
step = {h:?}
theta = {theta:?}
steps = 100000
[solver]
tolerance = 1e-10
[[materials]]
name = "m"
density = {RHO:?}
[[laws]]
materials = ["m", "m"]
law = "frictionless"
restitution = {e:?}
[[bodies]]
shape = "halfplane"
material = "m"
position = [0.0, 0.0]
fixed = true
[[bodies]]
shape = "disk"
material = "m"
radius = {R:?}
position = [0.0, {:?}]
"#,
        R + h0
    ))
}

/// e = 0.5, h0 = 0.5 m: the first rebound reaches e² h0 and the ball comes to rest at T = √(2 h0/g)(1 + e)/(1 − e)
/// (first fall t1, then bounces of durations 2 e^k v0 / g summing to
/// 2 t1 e/(1 − e)).
///
/// "At rest" at the end of a step: |v| ≤ g h (less than what gravity gives in one
/// step) and the gap is below g h² (the distance gravity moves it in one step); the
/// rest time is the first step after which it stays at rest until 1.5 T.
/// Tolerance: each bounce's impact is resolved to one step, and the Zeno sequence is
/// cut once the bounce speed is about g h, after n ≈ ln(v0/(g h))/ln(1/e) bounces;
/// so |T_h − T| ≲ (n + 2) h. With h = 1e-4 that is n ≈ 11.6, ≈ 14 h = 1.4 ms,
/// 0.15 % of T ≈ 0.958 s.
#[test]
fn bouncing_ball_comes_to_rest_at_zeno_time() {
    let (h0, e, h) = (0.5, 0.5, 1e-4);
    let mut s = bouncing(h0, e, h, 0.5);
    let t1 = (2.0 * h0 / G).sqrt();
    let t_rest = t1 * (1.0 + e) / (1.0 - e);
    let n_total = (1.5 * t_rest / h) as usize;
    let mut rest_since: Option<f64> = None;
    let mut bounces = 0;
    let mut vprev = 0.0;
    let mut apex1: f64 = 0.0;
    for _ in 0..n_total {
        step(&mut s);
        let b = &s.world.bodies;
        let (v, gap) = (b.vel[1], b.pos[1][1] - R);
        if vprev < 0.0 && v[1] > 0.0 {
            bounces += 1;
        }
        vprev = v[1];
        if bounces == 1 {
            apex1 = apex1.max(gap);
        }
        let at_rest = v[1].hypot(v[0]) <= G * h && gap.abs() <= G * h * h;
        match (at_rest, rest_since) {
            (true, None) => rest_since = Some(s.world.t),
            (false, Some(_)) => rest_since = None,
            _ => {}
        }
    }
    let t_num = rest_since.expect("the ball comes to rest");
    let n_bounces = ((G * t1) / (G * h)).ln() / (1.0 / e).ln();
    println!(
        "bounces seen: {bounces} (estimate {n_bounces:.1}); final gap {:.3e} m",
        s.world.bodies.pos[1][1] - R
    );
    assert_abs("rest time (s)", t_num, t_rest, (n_bounces + 2.0) * h);
    // first rebound height e² h0: with θ = ½ free flight keeps ½ v² + g y exactly, so
    // the ball reverses at some y_b ∈ [0, v0 h] with ½ v⁻² = g (h0 − y_b), and the
    // impact step moves it by −(1 − e) v0 h/2: |apex − e² h0| ≤ v0 h.
    let v0 = (2.0 * G * h0).sqrt();
    assert_abs("first rebound height (m)", apex1, e * e * h0, v0 * h);
}

/// θ = ½, e = 1, h0 = 0.5 m, h = 1e-3, 3 s (≈ 5 bounces): the total energy
/// (kinetic + gravity potential) is constant. With θ = ½ free flight keeps
/// ½ v² + g y exactly (y⁺ − y⁻ = h (v⁻ + v⁺)/2 and v⁺ − v⁻ = −g h), and an impact
/// step gives V⁺ = −V⁻ and so y⁺ = y⁻: the energy is kept up to rounding and the
/// solver tolerance (one contact, solved exactly). We assert 1e-9 relative.
#[test]
fn bouncing_ball_keeps_energy_with_theta_half_and_e_one() {
    let mut s = bouncing(0.5, 1.0, 1e-3, 0.5);
    let e0 = {
        let (k, p) = s.world.energies();
        k + p
    };
    let mut worst: f64 = 0.0;
    let mut bounces = 0;
    let mut vprev = 0.0;
    for _ in 0..3000 {
        step(&mut s);
        let (k, p) = s.world.energies();
        worst = worst.max(((k + p) - e0).abs() / e0);
        let v = s.world.bodies.vel[1][1];
        if vprev < 0.0 && v > 0.0 {
            bounces += 1;
        }
        vprev = v;
    }
    println!("{bounces} bounces; largest relative energy change {worst:.3e}");
    assert!(bounces >= 4, "the ball should bounce several times, saw {bounces}");
    assert_abs("largest relative energy change over 3 s", worst, 0.0, 1e-9);
}
