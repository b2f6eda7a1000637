//! Statics of stacked disks on a fixed floor (half-plane y = 0): a column, and a
//! three-disk pyramid whose standing depends on friction.

use crate::common::{assert_abs, assert_rel, contact_between, disk_mass, impulse_on_i, scene, steps, G};
use nscdd::scene::Scene;

const R: f64 = 0.05;
const RHO: f64 = 1000.0;
const H: f64 = 1e-3;

fn header(tol: f64, ordering: &str, mu: f64) -> String {
    format!(
        r#"
[time]
step = {H:?}
steps = 1000
[solver]
tolerance = {tol:?}
max_sweeps = 100000
ordering = "{ordering}"
seed = 7
[[materials]]
name = "m"
density = {RHO:?}
[[laws]]
materials = ["m", "m"]
friction = {mu:?}
[[bodies]]
name = "floor"
shape = "halfplane"
material = "m"
position = [0.0, 0.0]
fixed = true
"#
    )
}

fn disk(x: f64, y: f64) -> String {
    format!("[[bodies]]\nshape = \"disk\"\nmaterial = \"m\"\nradius = {R:?}\nposition = [{x:?}, {y:?}]\n")
}

/// A column of N = 10 equal disks at rest on the floor: after settling, the contact
/// under the k-th disk from the top carries the impulse k m g h per step.
///
/// Tolerance: the step problem is the chain W = (1/m)·tridiag(−1, 2, −1) (1 on the
/// floor contact), solved by NLGS to `tol` = 1e-6 in LMGC90's QM/16 norm, i.e. a
/// last sweep that changes W r by at most ~tol relative to |W r|. Gauss–Seidel on
/// this chain contracts by roughly ρ ≈ cos²(π/(2N+1)) ≈ 0.978 per sweep, so one cold solve
/// is within ~tol/(1 − ρ) ≈ 45 tol ≈ 5e-5 relative. The column does not move, so
/// every step is the same problem and the warm start carries the impulses over:
/// 200 steps of at least `check_every` = 10 sweeps are ≥ 2000 sweeps on one
/// problem, ρ^2000 ≈ 1e-19, and the settled impulses are exact up to rounding.
/// We assert 1e-9 relative on every contact, for the three visiting orders.
#[test]
fn column_contact_forces_are_k_m_g() {
    const N: usize = 10;
    let m = disk_mass(RHO, R);
    // NLGS in three orders, Anderson and Newton (storage order), NLGS over-relaxed
    for ordering in ["stored", "reversed", "shuffled", "anderson", "newton", "over-relaxed"] {
        let mut text = header(1e-6, ordering, 0.3);
        if ordering == "anderson" || ordering == "newton" {
            text = text.replace(&format!("ordering = \"{ordering}\""), &format!("method = \"{ordering}\""));
        }
        if ordering == "over-relaxed" {
            text = text.replace("ordering = \"over-relaxed\"", "relaxation = 1.2");
        }
        for k in 0..N {
            text += &disk(0.0, R + 2.0 * R * k as f64);
        }
        let mut s = scene(&text);
        steps(&mut s, 200);
        let c = &s.world.contacts;
        assert_eq!(c.len(), N, "one contact under each disk");
        let mut worst: f64 = 0.0;
        for a in 0..c.len() {
            let y = c.point[a][1];
            let above = s.world.bodies.pos.iter().skip(1).filter(|p| p[1] > y).count();
            let expected = above as f64 * m * G * H;
            worst = worst.max((c.r[a][0] - expected).abs() / expected);
            assert_rel(
                &format!("{ordering}: contact force under disk {above} from the top (N)"),
                c.r[a][0] / H,
                expected / H,
                1e-9,
            );
            assert_abs("tangential impulse (N s)", c.r[a][1], 0.0, 1e-15);
        }
        println!("{ordering}: worst relative error of the column forces {worst:.3e}");
        let vmax = s.world.bodies.vel.iter().map(|v| v[1].abs()).fold(0.0, f64::max);
        assert!(vmax < 1e-6, "{ordering}: the column is at rest, max |v_y| = {vmax:e}");
    }
}

/// The pyramid: bottom disks B (left, body 1) and C (right, body 2) at (∓R, R)
/// touching each other, the top disk A (body 3) at (0, R + √3 R) touching both.
/// Unit vector from B to A: e = (½, √3/2), tangent τ = (−√3/2, ½).
///
/// Statics (weight mg each). Unknowns: at A–B (and mirrored A–C) the force on A,
/// N_d e + T_d τ; at each floor contact the force on the bottom disk (±H, N_f); at
/// B–C the push s = N_bb ≥ 0 (its tangential part is 0, see below). Rank of the
/// 9 equilibrium equations in the 10 unknowns is 9, and a self-stress exists (the
/// symmetric one below), so the solutions form the one-parameter family in s:
///
/// ```text
///   A, vertical:    2 (N_d √3/2 + T_d/2) = mg            (each A contact: mg/2 up)
///   B, moment:      R H − R T_d = 0            ⇒ H = T_d
///   B, horizontal:  −N_d/2 + T_d √3/2 + H − s = 0
///   ⇒ N_d = mg/2 − (2 − √3) s,   T_d = H = (2 − √3) mg/2 + (2√3 − 3) s,
///     N_f = 3 mg / 2,            B–C tangential = 0.
/// ```
///
/// T_d/N_d grows with s, so the least friction is needed at s = 0:
/// T_d/N_d = 2 − √3 = tan 15° ≈ 0.268 at the disk–disk contacts, and
/// H/N_f = (2 − √3)/3 ≈ 0.089 at the floor. With one μ for all pairs the pyramid
/// stands iff μ ≥ μ* = 2 − √3. (If a non-symmetric solution existed, its average
/// with its mirror image would be a symmetric one, so the threshold holds for all.)
/// What the solver must return whatever s it picks: N_f = 3mg/2, the vertical
/// push mg/2 at each A contact, a zero B–C friction, and (N_d, T_d, H) on the family
/// line for its own s.
const MU_STAR: f64 = 0.267_949_192_431_122_7; // 2 − √3

fn pyramid(mu: f64, tol: f64, ordering: &str) -> Scene {
    let mut text = header(tol, ordering, mu);
    text += &disk(-R, R);
    text += &disk(R, R);
    text += &disk(0.0, R + 3f64.sqrt() * R);
    scene(&text)
}

/// μ = 1.05 μ*: the pyramid stands; contact forces are the statics' forces.
///
/// Tolerance: the five contacts form a small, well-conditioned problem; with the
/// solver tolerance 1e-10 and the warm start over 500 steps, the forces are at
/// solver precision. We assert 1e-6 relative (of mg h) on the forces and, for the
/// positions, 1e-9 R after 0.5 s: the per-step velocity error ~tol·g h integrated
/// over 500 steps is far below that.
#[test]
fn pyramid_stands_above_threshold() {
    let m = disk_mass(RHO, R);
    let w = m * G * H; // weight impulse per step
    let s3 = 3f64.sqrt();
    for ordering in ["stored", "reversed", "shuffled"] {
        let mut s = pyramid(1.05 * MU_STAR, 1e-10, ordering);
        let x0 = s.world.bodies.pos.clone();
        steps(&mut s, 500);
        let b = &s.world.bodies;
        let drift = (1..4)
            .map(|k| (b.pos[k][0] - x0[k][0]).hypot(b.pos[k][1] - x0[k][1]))
            .fold(0.0, f64::max);
        assert_abs(&format!("{ordering}: largest displacement after 0.5 s (m)"), drift, 0.0, 1e-9 * R);
        // floor contacts: vertical 3mg/2 each (determined)
        let mut h_floor = [0.0; 2];
        for (k, body) in [1u32, 2].into_iter().enumerate() {
            let a = contact_between(&s, body, 0).expect("floor contact");
            let p = impulse_on_i(&s, a);
            assert_rel(
                &format!("{ordering}: floor normal force under disk {body} (N)"),
                p[1] / H,
                1.5 * w / H,
                1e-6,
            );
            h_floor[k] = p[0];
        }
        // B–C contact: a push s ≥ 0, no friction
        let bc = contact_between(&s, 1, 2);
        let push = bc.map_or(0.0, |a| s.world.contacts.r[a][0]);
        if let Some(a) = bc {
            assert_abs(
                &format!("{ordering}: B–C friction (N)"),
                s.world.contacts.r[a][1] / H,
                0.0,
                1e-6 * w / H,
            );
        }
        println!("{ordering}: B–C push s = {:.6e} N (the statics' free parameter)", push / H);
        let nd = w / 2.0 - (2.0 - s3) * push;
        let td = (2.0 - s3) * w / 2.0 + (2.0 * s3 - 3.0) * push;
        for (body, sign) in [(1u32, 1.0), (2, -1.0)] {
            let a = contact_between(&s, body, 3).expect("top contact");
            // impulse on A: the contact's i is the bottom disk (lower id)
            let p = impulse_on_i(&s, a);
            let pa = [-p[0], -p[1]];
            let e = [sign * 0.5, s3 / 2.0];
            let tau = [-s3 / 2.0, sign * 0.5];
            assert_rel(
                &format!("{ordering}: vertical push on A at disk {body} (N)"),
                pa[1] / H,
                w / 2.0 / H,
                1e-6,
            );
            assert_rel(
                &format!("{ordering}: N_d at disk {body} (N)"),
                (pa[0] * e[0] + pa[1] * e[1]) / H,
                nd / H,
                1e-6,
            );
            assert_rel(
                &format!("{ordering}: |T_d| at disk {body} (N)"),
                (pa[0] * tau[0] + pa[1] * tau[1]).abs() / H,
                td / H,
                1e-6,
            );
        }
        assert_rel(&format!("{ordering}: floor friction H on B (N)"), h_floor[0] / H, td / H, 1e-6);
        assert_rel(&format!("{ordering}: floor friction H on C (N)"), -h_floor[1] / H, td / H, 1e-6);
    }
}

/// μ = 0.95 μ*: no static solution, the pyramid collapses: the top disk falls and the
/// bottom disks slide apart. Within 0.5 s the top has dropped by more than R/20 and
/// the bottom disks have separated (both would be 0 for a standing pyramid).
#[test]
fn pyramid_collapses_below_threshold() {
    for ordering in ["stored", "shuffled"] {
        let mut s = pyramid(0.95 * MU_STAR, 1e-8, ordering);
        let y0 = s.world.bodies.pos[3][1];
        steps(&mut s, 500);
        let b = &s.world.bodies;
        let drop = y0 - b.pos[3][1];
        let spread = b.pos[2][0] - b.pos[1][0] - 2.0 * R;
        println!("{ordering}: μ = 0.95 μ*: top dropped {drop:.4e} m, bottom gap {spread:.4e} m after 0.5 s");
        assert!(drop > R / 20.0, "{ordering}: the top should fall, dropped {drop:e}");
        assert!(spread > 0.0, "{ordering}: the bottom disks should separate, gap {spread:e}");
    }
}
