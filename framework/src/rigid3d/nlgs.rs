//! Non-linear Gauss–Seidel over the 3D contact set: the same sweep as in 2D
//! ([`crate::rigid2d::nlgs`]) with the 3D local velocity, impulse application and
//! one-contact solver ([`super::coulomb`]). The check pass, the stopping test and the
//! natural-map residual are the dimension-free ones of [`crate::norms`].

use super::contacts::{apply_with, local_velocity, Contacts3, InvMass3, InvMassOf, Split};
use super::coulomb::{self, Sym3};
use super::joint;
use crate::norms::{natural_map_sq, Sums};
use crate::solver::{SolveReport, SolverSettings};

/// One sweep; accumulates the check sums when `sums` is given. An empty `order`
/// means storage order.
#[inline(never)]
pub fn sweep(
    c: &mut Contacts3,
    vel: &mut [[f64; 6]],
    inv_m: &[[f64; 3]],
    inv_i: &[Sym3],
    order: &[u32],
    omega: f64,
    sums: Option<&mut Sums>,
) {
    sweep_with(c, vel, &Split(inv_m, inv_i), order, omega, sums);
}

/// [`sweep`] over copies whose M̂⁻¹ are [`InvMass3`] (NSCDD subdomains).
#[inline(never)]
pub fn sweep_split(c: &mut Contacts3, vel: &mut [[f64; 6]], inv: &[InvMass3], order: &[u32], omega: f64, sums: Option<&mut Sums>) {
    sweep_with(c, vel, inv, order, omega, sums);
}

#[inline(always)]
fn sweep_with<M: InvMassOf + ?Sized>(
    c: &mut Contacts3,
    vel: &mut [[f64; 6]],
    inv: &M,
    order: &[u32],
    omega: f64,
    mut sums: Option<&mut Sums>,
) {
    let m = c.len();
    let visit = |a: usize, vel: &mut [[f64; 6]], c: &mut Contacts3, sums: &mut Option<&mut Sums>| {
        let [bi, bj] = c.bodies[a];
        let (bi, bj) = (bi as usize, bj as usize);
        let f = &c.frame[a];
        let u = local_velocity(f, &vel[bi], &vel[bj]);
        let r = c.r[a];
        let blk = &c.block[a];
        let wr_old = coulomb::mul(&blk.w, r);
        let u0 = [u[0] - wr_old[0], u[1] - wr_old[1], u[2] - wr_old[2]];
        let t = c.target[a];
        let jt = c.joint[a];
        let mut rn = if jt.bonded() {
            joint::solve(&blk.w, &blk.pre, u0, t.u_target, t.mu, &jt, r)
        } else {
            coulomb::solve_pre_warm(&blk.w, &blk.pre, u0, t.u_target, t.mu, r)
        };
        if omega != 1.0 {
            for k in 0..3 {
                rn[k] = omega * rn[k] + (1.0 - omega) * r[k];
            }
        }
        let dr = [rn[0] - r[0], rn[1] - r[1], rn[2] - r[2]];
        if let Some(s) = sums.as_deref_mut() {
            let wr = coulomb::mul(&blk.w, rn);
            let du = [wr[0] - wr_old[0], wr[1] - wr_old[1], wr[2] - wr_old[2]];
            s.add(&r, &rn, &du, &wr_old, &wr);
        }
        if dr != [0.0; 3] {
            c.r[a] = rn;
            let f = c.frame[a];
            apply_with(&f, dr, bi, bj, vel, inv);
        }
    };
    if order.is_empty() {
        for a in 0..m {
            visit(a, vel, c, &mut sums);
        }
    } else {
        for &a in order {
            visit(a as usize, vel, c, &mut sums);
        }
    }
}

/// Runs sweeps until the criterion holds or `max_sweeps` is reached.
pub fn solve(
    c: &mut Contacts3,
    vel: &mut [[f64; 6]],
    inv_m: &[[f64; 3]],
    inv_i: &[Sym3],
    order: &[u32],
    s: &SolverSettings,
) -> SolveReport {
    if c.is_empty() {
        return SolveReport {
            converged: true,
            ..Default::default()
        };
    }
    let mut report = s.run_sweeps(|sums| sweep(c, vel, inv_m, inv_i, order, s.relaxation, sums));
    report.residual = residual(c, vel);
    report
}

/// Natural-map residual ‖F(r)‖/‖q‖ with the normal velocity shifted by the target.
pub fn residual(c: &Contacts3, vel: &[[f64; 6]]) -> f64 {
    let (f2, q2) = residual_parts(c, vel);
    if q2 == 0.0 {
        f2.sqrt()
    } else {
        (f2 / q2).sqrt()
    }
}

/// (‖F(r)‖², ‖q‖²) of [`residual`], for a stage that adds contacts of its own.
pub fn residual_parts(c: &Contacts3, vel: &[[f64; 6]]) -> (f64, f64) {
    let (mut f2, mut q2) = (0.0, 0.0);
    for a in 0..c.len() {
        let t = c.target[a];
        let mut u = c.local_velocity(a, vel);
        u[0] -= t.u_target;
        let jt = c.joint[a];
        f2 += if jt.bonded() {
            joint::natural_map_sq(c.r[a], u, t.mu, &jt)
        } else {
            natural_map_sq(&c.r[a], &u, t.mu)
        };
        let q = [c.u_free[a][0] - t.u_target, c.u_free[a][1], c.u_free[a][2]];
        q2 += q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
    }
    (f2, q2)
}
