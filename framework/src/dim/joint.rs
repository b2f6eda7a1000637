//! Bonded mortar joints: the one-contact solver of the law `mohr_coulomb`.
//!
//! A contact point α of a bonded joint stands for the tributary area A_α of the
//! joint (given by the detector: the overlap polygon of two faces shared by its
//! corners). Over a step h, cohesion c and tensile strength σ_t (Pa) become the
//! impulse strengths `C = c A_α h` and `T = σ_t A_α h`, with `T ≤ C/μ`. An intact
//! joint admits the impulses of the Mohr–Coulomb cone cut at the tension T,
//!
//! ```text
//!   K_c = { r :  r_n ≥ −T,  |r_t| ≤ C + μ r_n },
//! ```
//!
//! and its law is the Signorini–Coulomb law of [`super::coulomb3`] on that set: the
//! joint stays closed (u_n = ū) while r_n > −T and may open (u_n ≥ ū) only at
//! r_n = −T; it sticks (u_t = 0) inside the cone and slides with r_t opposite to u_t
//! on its mantle. With the apex shift `s = C/μ` and `r̂ = r + s e_n`, the cone part
//! is the plain Coulomb cone `|r̂_t| ≤ μ r̂_n`, so the solver reuses the exact
//! one-contact solver:
//!
//! 1. **Stick**: `r = −W⁻¹ (u0 − ū e_n)` if it lies in K_c.
//! 2. **Cone**: r̂ from `coulomb::solve` with `u0 − s W e_n`; `r = r̂ − s e_n` if
//!    `r_n ≥ −T` (a solution on the uncut cone that satisfies the cut is one of
//!    the cut problem: the two sets coincide around it).
//! 3. **Cut-off**: `r_n = −T`; r_t minimises `½ r_tᵀ W_tt r_t + (u0_t + W_tn r_n)·r_t`
//!    on the disk `|r_t| ≤ C − μT`, accepted if the joint opens (`u_n ≥ ū`).
//! 4. Otherwise (the rim of the cut, degenerate blocks) the projected fixed point
//!    of `coulomb`, with the projection on K_c.
//!
//! **Failure** is decided once per step, on the converged impulses: the joint holds
//! while its sticking impulse lies in K_c (the strength is not exhausted); once it
//! does not, the contact loses its bond for good and obeys `coulomb` with e = 0.
//! New contacts are never bonded: only contacts within `bond_gap` at the first step
//! are, and a bond survives only on the same contact point (the same key at the
//! same place, or the nearest point of the same pair within the alert distance
//! when a polygon's corners are renumbered: `engine3::build_contacts`).

use super::coulomb3::{self as coulomb, disk_min, Pre3, Sym3};
use crate::norms::project_cone;
use serde::{Deserialize, Serialize};

/// The strengths of one bonded contact over the step (impulses, N·s); zero for a
/// contact without a bond.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[repr(C)]
pub struct Joint {
    /// Apex shift s = C/μ.
    pub shift: f64,
    /// Tension cut-off T ≤ s.
    pub tension: f64,
}

impl Joint {
    /// A bond whose strengths are not known yet (a restarted state): they are
    /// computed from the law at the next step.
    pub const RESTORED: Joint = Joint {
        shift: f64::MIN_POSITIVE,
        tension: 0.0,
    };

    /// The strengths of a bonded contact of tributary area `area` over a step h,
    /// from the law's cohesion c, tensile strength σ_t and friction μ:
    /// `s = c A h / μ`, `T = min(σ_t A h, s)`.
    pub fn of(cohesion: f64, tensile: f64, mu: f64, area: f64, h: f64) -> Joint {
        let shift = cohesion * area * h / mu;
        Joint {
            shift,
            // T ≤ s also after round-off (the default σ_t is c/μ)
            tension: (tensile * area * h).min(shift),
        }
    }

    /// Whether the contact is bonded.
    #[inline(always)]
    pub fn bonded(&self) -> bool {
        self.shift > 0.0
    }
}

/// Projection on K_c: the shifted cone, then the cut disk if the cut is violated.
pub fn project(z: [f64; 3], mu: f64, j: &Joint) -> [f64; 3] {
    let p = project_cone(&[z[0] + j.shift, z[1], z[2]], mu);
    if p[0] - j.shift >= -j.tension {
        return [p[0] - j.shift, p[1], p[2]];
    }
    let rad = mu * (j.shift - j.tension);
    let zt = (z[1] * z[1] + z[2] * z[2]).sqrt();
    let k = if zt > rad { rad / zt } else { 1.0 };
    [-j.tension, k * z[1], k * z[2]]
}

/// Whether r lies in K_c, up to `tol` relative to the strength scale s + |r_n|.
fn admissible(r: [f64; 3], mu: f64, j: &Joint, tol: f64) -> bool {
    let scale = j.shift + r[0].abs();
    r[0] >= -j.tension - tol * scale && (r[1] * r[1] + r[2] * r[2]).sqrt() <= mu * (r[0] + j.shift + tol * scale)
}

/// The sticking impulse −W⁻¹ (u0 − ū e_n), when W is invertible.
#[inline]
fn stick(pre: &Pre3, u0: [f64; 3], u_target: f64) -> Option<[f64; 3]> {
    (pre.singular == 0).then(|| coulomb::mul(&pre.inv, [u_target - u0[0], -u0[1], -u0[2]]))
}

/// Solves the one-contact problem of an intact joint (see the module docs);
/// `prev` is the contact's previous impulse.
pub fn solve(w: &Sym3, pre: &Pre3, u0: [f64; 3], u_target: f64, mu: f64, j: &Joint, prev: [f64; 3]) -> [f64; 3] {
    // 1. stick
    if let Some(r) = stick(pre, u0, u_target) {
        if admissible(r, mu, j, 1e-12) {
            return r;
        }
    }
    // 2. the cone, shifted to its apex
    let s = j.shift;
    let u0s = [u0[0] - s * w[0], u0[1] - s * w[1], u0[2] - s * w[2]];
    let rh = coulomb::solve_pre_warm(w, pre, u0s, u_target, mu, [prev[0] + s, prev[1], prev[2]]);
    if rh[0] - s >= -j.tension {
        return [rh[0] - s, rh[1], rh[2]];
    }
    // 3. the cut-off: r_n = −T, r_t on the disk of radius C − μT
    let rn = -j.tension;
    let b = [u0[1] + w[1] * rn, u0[2] + w[2] * rn];
    if let Some(rt) = disk_min(w[3], w[4], w[5], b, mu * (s - j.tension)) {
        let un = w[0] * rn + w[1] * rt[0] + w[2] * rt[1] + u0[0];
        if un >= u_target - 1e-12 * (u_target.abs() + u0[0].abs()) {
            return [rn, rt[0], rt[1]];
        }
    }
    // the rim of the cut, degenerate blocks: the projected fixed point on K_c
    coulomb::projected_fixed_point(w, u0, u_target, mu, 4000, j.shift, |z| project(z, mu, j))
}

/// Whether an intact joint still holds at the end of the step: its sticking
/// impulse for `u0 = u − W r` lies in K_c, up to `tol` relative to its strength
/// (the solver's tolerance: an NLGS converged to it leaves residual velocities that
/// would otherwise read as a strength exceeded by that much). A singular W has no
/// sticking impulse: the joint holds while the contact does not move,
/// |u − ū e_n| ≤ tol |u0 − ū e_n| with u = W r + u0.
#[allow(clippy::too_many_arguments)]
pub fn holds(w: &Sym3, pre: &Pre3, r: [f64; 3], u0: [f64; 3], u_target: f64, mu: f64, j: &Joint, tol: f64) -> bool {
    match stick(pre, u0, u_target) {
        Some(rs) => admissible(rs, mu, j, tol),
        None => {
            let wr = coulomb::mul(w, r);
            let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let moved = len([wr[0] + u0[0] - u_target, wr[1] + u0[1], wr[2] + u0[2]]);
            moved <= tol * len([u0[0] - u_target, u0[1], u0[2]])
        }
    }
}

/// The squared natural-map residual of a joint contact, `|r − P_Kc(r − ũ)|²` with
/// De Saxcé's `ũ = (u_n − ū + μ|u_t|, u_t)`; `u` is already shifted by ū.
pub fn natural_map_sq(r: [f64; 3], u: [f64; 3], mu: f64, j: &Joint) -> f64 {
    let ut = (u[1] * u[1] + u[2] * u[2]).sqrt();
    let p = project([r[0] - u[0] - mu * ut, r[1] - u[1], r[2] - u[2]], mu, j);
    (0..3).map(|k| (r[k] - p[k]) * (r[k] - p[k])).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::coulomb3::precompute;

    fn check(w: &Sym3, u0: [f64; 3], mu: f64, j: &Joint) -> [f64; 3] {
        let r = solve(w, &precompute(w), u0, 0.0, mu, j, [0.0; 3]);
        let wr = coulomb::mul(w, r);
        let u = [wr[0] + u0[0], wr[1] + u0[1], wr[2] + u0[2]];
        let scale = u0.iter().map(|x| x.abs()).sum::<f64>() + j.shift;
        let res = natural_map_sq(r, u, mu, j).sqrt();
        assert!(res <= 1e-9 * scale, "w {w:?} u0 {u0:?} r {r:?} u {u:?} res {res:e}");
        r
    }

    #[test]
    fn the_four_regimes() {
        let w: Sym3 = [2.0, 0.0, 0.0, 3.0, 0.0, 3.0];
        let j = Joint { shift: 1.0, tension: 0.4 };
        let mu = 0.5;
        // pulled apart gently: sticks in tension (r_n = −0.2 ≥ −T)
        let r = check(&w, [0.4, 0.0, 0.0], mu, &j);
        assert!((r[0] + 0.2).abs() < 1e-15 && r[1] == 0.0);
        // pulled harder: opens at the cut-off
        let r = check(&w, [2.0, 0.0, 0.0], mu, &j);
        assert_eq!(r[0], -0.4);
        // sheared under zero normal load: sticks while |r_t| ≤ C = μ s = 0.5
        let r = check(&w, [0.0, 1.2, 0.0], mu, &j);
        assert!((r[1] + 0.4).abs() < 1e-15);
        // sheared beyond: slides on the mantle, |r_t| = C + μ r_n
        let r = check(&w, [-1.0, 3.0, 0.0], mu, &j);
        assert!(r[0] > 0.0 && (r[1].abs() - mu * (r[0] + 1.0)).abs() < 1e-12);
        // pulled and sheared: opens with |r_t| on the disk C − μT
        let r = check(&w, [3.0, 3.0, 1.0], mu, &j);
        assert_eq!(r[0], -0.4);
        assert!(((r[1] * r[1] + r[2] * r[2]).sqrt() - mu * 0.6).abs() < 1e-12);
    }

    #[test]
    fn coupled_blocks() {
        // lever arms couple the normal and the tangent: pseudo-random blocks
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for _ in 0..2000 {
            let a: [[f64; 3]; 3] = std::array::from_fn(|_| std::array::from_fn(|_| rnd()));
            let m = |p: usize, q: usize| (0..3).map(|k| a[p][k] * a[q][k]).sum::<f64>() + if p == q { 0.3 } else { 0.0 };
            let w: Sym3 = [m(0, 0), m(0, 1), m(0, 2), m(1, 1), m(1, 2), m(2, 2)];
            let u0 = [2.0 * rnd(), 2.0 * rnd(), 2.0 * rnd()];
            let mu = 0.2 + rnd().abs();
            let s = rnd().abs();
            let j = Joint {
                shift: s,
                tension: s * rnd().abs(),
            };
            check(&w, u0, mu, &j);
        }
    }

    #[test]
    fn failure_test() {
        let w: Sym3 = [2.0, 0.0, 0.0, 3.0, 0.0, 3.0];
        let pre = precompute(&w);
        let j = Joint { shift: 1.0, tension: 0.4 };
        assert!(holds(&w, &pre, [0.0; 3], [0.4, 0.0, 0.0], 0.0, 0.5, &j, 1e-9));
        assert!(holds(&w, &pre, [0.0; 3], [0.0, 0.0, 0.0], 0.0, 0.5, &j, 1e-9));
        assert!(!holds(&w, &pre, [0.0; 3], [2.0, 0.0, 0.0], 0.0, 0.5, &j, 1e-9));
        assert!(!holds(&w, &pre, [0.0; 3], [-1.0, 3.0, 0.0], 0.0, 0.5, &j, 1e-9));
        // an unbonded contact at rest under zero load holds trivially
        assert!(holds(&w, &pre, [0.0; 3], [0.0; 3], 0.0, 0.5, &Joint::RESTORED, 1e-9));
        assert!(project([-5.0, 0.0, 0.0], 0.5, &j) == [-0.4, 0.0, 0.0]);
    }
}
