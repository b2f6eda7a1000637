//! The exact one-contact 2D Signorini–Coulomb solver.
//!
//! For one contact α with diagonal Delassus block `W = [[W_nn, W_nt], [W_nt, W_tt]]`
//! and the part of its local velocity that does not depend on its own impulse,
//! `u0 = u − W r`, find `r = (r_n, r_t)` with `u = W r + u0` such that
//!
//! ```text
//!   s = u_n − ū ≥ 0,   r_n ≥ 0,   s · r_n = 0        (Signorini, shifted by ū)
//!   |r_t| ≤ μ r_n,     |r_t| < μ r_n ⇒ u_t = 0,
//!   u_t ≠ 0 ⇒ r_t = −μ r_n sign(u_t)                  (Coulomb)
//! ```
//!
//! `ū` is the law's target normal velocity (restitution and gap prediction, see
//! `law`). In 2D the Coulomb cone has only four faces, so the solution is found by
//! enumerating the cases: no contact, sticking, sliding forwards, sliding backwards;
//! the first case that satisfies all its inequalities is returned. That is exact, not
//! iterative. When W is singular or μ is so large that no case is consistent (a
//! non-unique local problem), a projected fixed point on the local problem is used
//! as a fallback.

use super::joint::Joint;
use crate::norms::project_cone;

/// Relative tolerance used to accept a case of the enumeration.
const ACCEPT: f64 = 1e-12;

/// Solves the one-contact problem. `w = [W_nn, W_nt, W_tt]`, `u0 = [u0_n, u0_t]`.
#[inline]
pub fn solve(w: [f64; 3], u0: [f64; 2], u_target: f64, mu: f64) -> [f64; 2] {
    let [wnn, wnt, wtt] = w;
    let s0 = u0[0] - u_target;
    // 1. no contact: the free part already separates.
    if s0 >= 0.0 {
        return [0.0, 0.0];
    }
    let scale = wnn.abs().max(wtt.abs());
    // 2. stick: W r = -(s0, u0_t).
    let det = wnn * wtt - wnt * wnt;
    if det > ACCEPT * scale * scale {
        let rn = (-s0 * wtt + u0[1] * wnt) / det;
        let rt = (-u0[1] * wnn + s0 * wnt) / det;
        if rn >= 0.0 && rt.abs() <= mu * rn * (1.0 + ACCEPT) {
            return [rn, rt];
        }
    }
    // 3. slide with u_t of sign σ, r_t = −σ μ r_n.
    for sigma in [1.0_f64, -1.0] {
        let d = wnn - sigma * mu * wnt;
        if d > ACCEPT * scale {
            let rn = -s0 / d;
            let rt = -sigma * mu * rn;
            let ut = wnt * rn + wtt * rt + u0[1];
            if sigma * ut >= -ACCEPT * (u0[1].abs() + scale * rn) {
                return [rn, rt];
            }
        }
    }
    fallback(w, u0, u_target, mu)
}

/// Quantities of a block W that [`solve_pre`] reuses at every sweep: the inverse
/// `W⁻¹ = [i_nn, i_nt, i_tt]` (zeros when W is singular) and `1 / (W_nn − σ μ W_nt)`
/// for σ = +1, −1 (zero when that slide case has no positive pivot).
pub fn precompute(w: [f64; 3], mu: f64) -> [f64; 5] {
    let [wnn, wnt, wtt] = w;
    let scale = wnn.abs().max(wtt.abs());
    let det = wnn * wtt - wnt * wnt;
    let mut p = [0.0; 5];
    if det > ACCEPT * scale * scale {
        p[0] = wtt / det;
        p[1] = -wnt / det;
        p[2] = wnn / det;
    }
    for (k, sigma) in [(3, 1.0), (4, -1.0)] {
        let d = wnn - sigma * mu * wnt;
        if d > ACCEPT * scale {
            p[k] = 1.0 / d;
        }
    }
    p
}

/// [`solve`] with the block's [`precompute`]d inverses: the same enumeration, without
/// divisions. Used by the NLGS sweeps.
#[inline(always)]
pub fn solve_pre(w: [f64; 3], p: &[f64; 5], u0: [f64; 2], u_target: f64, mu: f64) -> [f64; 2] {
    let s0 = u0[0] - u_target;
    if s0 >= 0.0 {
        return [0.0, 0.0];
    }
    if p[0] != 0.0 || p[2] != 0.0 {
        let rn = -(p[0] * s0 + p[1] * u0[1]);
        let rt = -(p[1] * s0 + p[2] * u0[1]);
        if rn >= 0.0 && rt.abs() <= mu * rn * (1.0 + ACCEPT) {
            return [rn, rt];
        }
    }
    let scale = w[0].abs().max(w[2].abs());
    for (k, sigma) in [(3, 1.0_f64), (4, -1.0)] {
        if p[k] > 0.0 {
            let rn = -s0 * p[k];
            let rt = -sigma * mu * rn;
            let ut = w[1] * rn + w[2] * rt + u0[1];
            if sigma * ut >= -ACCEPT * (u0[1].abs() + scale * rn) {
                return [rn, rt];
            }
        }
    }
    fallback(w, u0, u_target, mu)
}

/// x clamped to [−b, b]; never panics (`f64::clamp` does on a NaN bound, which
/// overflowing input can produce): a NaN bound leaves x, which the caller's
/// residual then reports.
#[inline]
fn clamp_sym(x: f64, b: f64) -> f64 {
    x.max(-b).min(b)
}

/// Projected fixed point `r ← P_K(r − ρ (u(r) − ū e_n))` for degenerate blocks.
#[cold]
fn fallback(w: [f64; 3], u0: [f64; 2], u_target: f64, mu: f64) -> [f64; 2] {
    let [wnn, wnt, wtt] = w;
    let rho = 1.0 / wnn.max(wtt).max(f64::MIN_POSITIVE);
    let mut r = [0.0_f64, 0.0];
    for _ in 0..200 {
        let un = wnn * r[0] + wnt * r[1] + u0[0] - u_target;
        let ut = wnt * r[0] + wtt * r[1] + u0[1];
        let rn = (r[0] - rho * un).max(0.0);
        let rt = clamp_sym(r[1] - rho * ut, mu * rn);
        let change = (rn - r[0]).abs() + (rt - r[1]).abs();
        r = [rn, rt];
        if change <= 1e-14 * (rn.abs() + rt.abs()) {
            break;
        }
    }
    r
}

/// The sticking impulse −W⁻¹ (u0 − ū e_n) from the precomputed inverse, when W is
/// invertible.
#[inline]
fn stick(p: &[f64; 5], u0: [f64; 2], u_target: f64) -> Option<[f64; 2]> {
    let s0 = u0[0] - u_target;
    (p[0] != 0.0 || p[2] != 0.0).then(|| [-(p[0] * s0 + p[1] * u0[1]), -(p[1] * s0 + p[2] * u0[1])])
}

/// Projection on a 2D joint's set K_c (`super::joint`): the cone shifted to its
/// apex −s e_n, then the cut r_n = −T.
pub fn project_joint(z: [f64; 2], mu: f64, j: &Joint) -> [f64; 2] {
    let p = project_cone(&[z[0] + j.shift, z[1]], mu);
    if p[0] - j.shift >= -j.tension {
        return [p[0] - j.shift, p[1]];
    }
    let rad = mu * (j.shift - j.tension);
    [-j.tension, clamp_sym(z[1], rad)]
}

/// Whether r lies in K_c up to `tol` relative to the strength scale s + |r_n|.
fn joint_admissible(r: [f64; 2], mu: f64, j: &Joint, tol: f64) -> bool {
    let scale = j.shift + r[0].abs();
    r[0] >= -j.tension - tol * scale && r[1].abs() <= mu * (r[0] + j.shift + tol * scale)
}

/// The one-contact problem of an intact 2D mortar joint: the same four cases as the
/// 3D solver (`super::joint::solve`): stick, the cone shifted to its apex (this
/// module's exact enumeration), the cut-off r_n = −T with r_t minimising
/// `½ W_tt r_t² + (u0_t + W_tn r_n) r_t` on `|r_t| ≤ C − μT`, and the projected fixed
/// point on K_c for degenerate blocks.
#[allow(clippy::too_many_arguments)]
pub fn solve_joint(w: [f64; 3], p: &[f64; 5], u0: [f64; 2], u_target: f64, mu: f64, j: &Joint, _prev: [f64; 2]) -> [f64; 2] {
    if let Some(r) = stick(p, u0, u_target) {
        if joint_admissible(r, mu, j, 1e-12) {
            return r;
        }
    }
    let s = j.shift;
    let rh = solve_pre(w, p, [u0[0] - s * w[0], u0[1] - s * w[1]], u_target, mu);
    if rh[0] - s >= -j.tension {
        return [rh[0] - s, rh[1]];
    }
    let rn = -j.tension;
    let b = u0[1] + w[1] * rn;
    if w[2] > 0.0 {
        let rad = mu * (s - j.tension);
        let rt = clamp_sym(-b / w[2], rad);
        let un = w[0] * rn + w[1] * rt + u0[0];
        if un >= u_target - 1e-12 * (u_target.abs() + u0[0].abs()) {
            return [rn, rt];
        }
    }
    joint_fallback(w, u0, u_target, mu, j)
}

/// Projected fixed point on K_c for degenerate joint blocks.
#[cold]
fn joint_fallback(w: [f64; 3], u0: [f64; 2], u_target: f64, mu: f64, j: &Joint) -> [f64; 2] {
    let [wnn, wnt, wtt] = w;
    let rho = 1.0 / wnn.max(wtt).max(f64::MIN_POSITIVE);
    let mut r = [0.0_f64, 0.0];
    for _ in 0..4000 {
        let un = wnn * r[0] + wnt * r[1] + u0[0] - u_target;
        let ut = wnt * r[0] + wtt * r[1] + u0[1];
        let next = project_joint([r[0] - rho * un, r[1] - rho * ut], mu, j);
        let change = (next[0] - r[0]).abs() + (next[1] - r[1]).abs();
        r = next;
        if change <= 1e-14 * (r[0].abs() + r[1].abs() + j.shift) {
            break;
        }
    }
    r
}

/// Whether an intact 2D joint holds at the end of the step (`super::joint::holds`).
#[allow(clippy::too_many_arguments)]
pub fn joint_holds(w: [f64; 3], p: &[f64; 5], r: [f64; 2], u0: [f64; 2], u_target: f64, mu: f64, j: &Joint, tol: f64) -> bool {
    match stick(p, u0, u_target) {
        Some(rs) => joint_admissible(rs, mu, j, tol),
        None => {
            let moved = [w[0] * r[0] + w[1] * r[1] + u0[0] - u_target, w[1] * r[0] + w[2] * r[1] + u0[1]];
            let len = |v: [f64; 2]| (v[0] * v[0] + v[1] * v[1]).sqrt();
            len(moved) <= tol * len([u0[0] - u_target, u0[1]])
        }
    }
}

/// `|r − P_Kc(r − ũ)|²` of a 2D joint, with `ũ = (u_n − ū + μ|u_t|, u_t)` (`u`
/// already shifted by ū).
pub fn joint_natural_map_sq(r: [f64; 2], u: [f64; 2], mu: f64, j: &Joint) -> f64 {
    let p = project_joint([r[0] - u[0] - mu * u[1].abs(), r[1] - u[1]], mu, j);
    (r[0] - p[0]).powi(2) + (r[1] - p[1]).powi(2)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(w: [f64; 3], u0: [f64; 2], ut: f64, mu: f64) {
        let r = solve(w, u0, ut, mu);
        let un = w[0] * r[0] + w[1] * r[1] + u0[0] - ut;
        let utan = w[1] * r[0] + w[2] * r[1] + u0[1];
        let tol = 1e-9 * (1.0 + u0[0].abs() + u0[1].abs());
        assert!(r[0] >= 0.0 && un >= -tol, "{r:?} {un}");
        assert!((r[0] * un).abs() <= tol * (1.0 + r[0]));
        assert!(r[1].abs() <= mu * r[0] + tol);
        if r[1].abs() < mu * r[0] - tol {
            assert!(utan.abs() <= tol, "stick but u_t = {utan}");
        } else if r[0] > tol {
            assert!(utan * r[1] <= tol, "slide against friction");
        }
    }

    #[test]
    fn cases() {
        let w = [2.0, 0.3, 1.5];
        check(w, [1.0, 0.2], 0.0, 0.5); // separating
        check(w, [-1.0, 0.0], 0.0, 0.5); // stick
        check(w, [-1.0, 3.0], 0.0, 0.5); // slide +
        check(w, [-1.0, -3.0], 0.0, 0.5); // slide -
        check(w, [-1.0, -3.0], 0.0, 0.0); // frictionless
        check(w, [-1.0, -3.0], 0.5, 100.0); // huge mu
        check([1.0, 0.99, 1.0], [-1.0, 2.0], 0.0, 10.0); // nearly singular
        check([1.0, 1.0, 1.0], [-1.0, -1.0], 0.0, 10.0); // singular, many solutions
    }

    #[test]
    fn precomputed_agrees() {
        let mut s = 99u64;
        let mut next = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 11) as f64) / ((1u64 << 53) as f64)
        };
        for _ in 0..20000 {
            let (a, c) = (next() * 3.0 + 0.01, next() * 3.0 + 0.01);
            let w = [a, (next() * 2.0 - 1.0) * (a * c).sqrt(), c];
            let mu = next() * 5.0;
            let u0 = [next() * 4.0 - 2.0, next() * 4.0 - 2.0];
            let (r1, r2) = (solve(w, u0, 0.1, mu), solve_pre(w, &precompute(w, mu), u0, 0.1, mu));
            assert!(
                (r1[0] - r2[0]).abs() + (r1[1] - r2[1]).abs() <= 1e-9 * (1.0 + r1[0].abs()),
                "{r1:?} {r2:?}"
            );
        }
    }

    #[test]
    fn random_blocks() {
        let mut s = 12345u64;
        let mut next = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 11) as f64) / ((1u64 << 53) as f64)
        };
        for _ in 0..20000 {
            let a = next() * 3.0 + 0.01;
            let c = next() * 3.0 + 0.01;
            let b = (next() * 2.0 - 1.0) * (a * c).sqrt();
            let mu = next() * 5.0;
            check([a, b, c], [next() * 4.0 - 2.0, next() * 4.0 - 2.0], next() - 0.5, mu);
        }
    }

    #[test]
    fn joint_regimes() {
        let w = [2.0, 0.0, 3.0];
        let j = Joint { shift: 1.0, tension: 0.4 };
        let mu = 0.5;
        let p = precompute(w, mu);
        let check = |u0: [f64; 2]| {
            let r = solve_joint(w, &p, u0, 0.0, mu, &j, [0.0; 2]);
            let u = [w[0] * r[0] + w[1] * r[1] + u0[0], w[1] * r[0] + w[2] * r[1] + u0[1]];
            let res = joint_natural_map_sq(r, u, mu, &j).sqrt();
            assert!(res <= 1e-9 * (u0[0].abs() + u0[1].abs() + 1.0), "u0 {u0:?} r {r:?} res {res:e}");
            r
        };
        // pulled apart gently: sticks in tension (r_n = −0.2 ≥ −T)
        let r = check([0.4, 0.0]);
        assert!((r[0] + 0.2).abs() < 1e-15 && r[1] == 0.0);
        // pulled harder: opens at the cut-off
        assert_eq!(check([2.0, 0.0])[0], -0.4);
        // sheared under zero normal load: sticks while |r_t| ≤ C = μ s = 0.5
        assert!((check([0.0, 1.2])[1] + 0.4).abs() < 1e-15);
        // sheared beyond: slides on the mantle, |r_t| = C + μ r_n
        let r = check([-1.0, 3.0]);
        assert!(r[0] > 0.0 && (r[1].abs() - mu * (r[0] + 1.0)).abs() < 1e-12);
        // pulled and sheared: the cut-off, |r_t| at the disk's rim μ (s − T)
        let r = check([2.0, 5.0]);
        assert!(r[0] == -0.4 && (r[1] + 0.3).abs() < 1e-12);
        assert!(joint_holds(w, &p, [-0.2, 0.0], [0.4, 0.0], 0.0, mu, &j, 1e-9));
        assert!(!joint_holds(w, &p, [-0.4, 0.0], [2.0, 0.0], 0.0, mu, &j, 1e-9));
    }
}
