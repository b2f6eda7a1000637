//! Non-linear Gauss–Seidel (NLGS) over the 2D contact set.
//!
//! One sweep visits the contacts in the chosen order; for contact α it forms the
//! current local velocity `u_α = H_αᵀ V` from the body velocities, removes its own
//! contribution `u0 = u_α − W_αα r_α`, solves the one-contact problem exactly
//! ([`super::coulomb::solve`]), relaxes `r ← ω r_new + (1 − ω) r_old`, and updates the
//! two bodies: `V += M̂⁻¹ H_α Δr_α`. Every `check_every` sweeps the sweep is also a
//! check pass (see [`crate::norms`]). The loop holds only slices of plain data: no
//! allocation and no dynamic dispatch per contact.

use super::{contacts::Contacts2, coulomb};
use crate::norms::{natural_map_sq, Norms, Sums};
use crate::solver::{Ordering, SolveReport, SolverSettings};
use rand::seq::SliceRandom;
use rand::SeedableRng;

/// Fills `order` with the visiting order of this step's contacts.
pub fn make_order(order: &mut Vec<u32>, n: usize, s: &SolverSettings, step: u64) {
    order.clear();
    order.extend(0..n as u32);
    match s.ordering {
        Ordering::Stored => {}
        Ordering::Reversed => order.reverse(),
        Ordering::Shuffled => {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(s.seed ^ step.wrapping_mul(0x9E37_79B9_7F4A_7C15));
            order.shuffle(&mut rng);
        }
    }
}

/// One NLGS sweep; accumulates the check sums when `sums` is given.
#[inline(never)]
pub fn sweep(c: &mut Contacts2, vel: &mut [[f64; 3]], inv_mass: &[[f64; 3]], order: &[u32], omega: f64, mut sums: Option<&mut Sums>) {
    for &a in order {
        let a = a as usize;
        let u = c.local_velocity(a, vel);
        let r = c.r[a];
        let w = c.w[a];
        let wr_old = [w[0] * r[0] + w[1] * r[1], w[1] * r[0] + w[2] * r[1]];
        let u0 = [u[0] - wr_old[0], u[1] - wr_old[1]];
        let mut rn = coulomb::solve(w, u0, c.u_target[a], c.mu[a]);
        if omega != 1.0 {
            rn = [omega * rn[0] + (1.0 - omega) * r[0], omega * rn[1] + (1.0 - omega) * r[1]];
        }
        let dr = [rn[0] - r[0], rn[1] - r[1]];
        if let Some(s) = sums.as_deref_mut() {
            let wr = [w[0] * rn[0] + w[1] * rn[1], w[1] * rn[0] + w[2] * rn[1]];
            let du = [wr[0] - wr_old[0], wr[1] - wr_old[1]];
            s.add(&r, &rn, &du, &wr_old, &wr);
        }
        if dr[0] != 0.0 || dr[1] != 0.0 {
            c.r[a] = rn;
            c.apply(a, dr, vel, inv_mass);
        }
    }
}

/// Runs sweeps until the criterion holds or `max_sweeps` is reached.
pub fn solve(c: &mut Contacts2, vel: &mut [[f64; 3]], inv_mass: &[[f64; 3]], order: &[u32], s: &SolverSettings) -> SolveReport {
    let mut report = SolveReport::default();
    if c.is_empty() {
        report.converged = true;
        return report;
    }
    let k = s.check_every.max(1);
    while report.sweeps < s.max_sweeps {
        report.sweeps += 1;
        let check = report.sweeps % k == 0 || report.sweeps == s.max_sweeps;
        if check {
            let mut sums = Sums::default();
            sweep(c, vel, inv_mass, order, s.relaxation, Some(&mut sums));
            report.norms = Norms::from_sums(&sums, s.tolerance);
            if report.norms.converged(s.norm) {
                report.converged = true;
                break;
            }
        } else {
            sweep(c, vel, inv_mass, order, s.relaxation, None);
        }
    }
    report.residual = residual(c, vel);
    report
}

/// Natural-map residual ‖F(r)‖/‖q‖ of the step's problem, with the normal velocity
/// shifted by the law's target (u_n − ū) and q the shifted free velocity.
pub fn residual(c: &Contacts2, vel: &[[f64; 3]]) -> f64 {
    let mut f2 = 0.0;
    let mut q2 = 0.0;
    for a in 0..c.len() {
        let mut u = c.local_velocity(a, vel);
        u[0] -= c.u_target[a];
        f2 += natural_map_sq(&c.r[a], &u, c.mu[a]);
        let q = [c.u_free[a][0] - c.u_target[a], c.u_free[a][1]];
        q2 += q[0] * q[0] + q[1] * q[1];
    }
    if q2 == 0.0 {
        f2.sqrt()
    } else {
        (f2 / q2).sqrt()
    }
}
