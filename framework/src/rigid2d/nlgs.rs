//! Non-linear Gauss–Seidel (NLGS) over the 2D contact set.
//!
//! One sweep visits the contacts in the chosen order; for contact α it forms the
//! current local velocity `u_α = H_αᵀ V` from the body velocities, removes its own
//! contribution `u0 = u_α − W_αα r_α`, solves the one-contact problem exactly
//! ([`super::coulomb::solve`]), relaxes `r ← ω r_new + (1 − ω) r_old`, and updates the
//! two bodies: `V += M̂⁻¹ H_α Δr_α`. Every `check_every` sweeps the sweep is also a
//! check pass (see [`crate::norms`]). The loop holds only slices of plain data: no
//! allocation and no dynamic dispatch per contact.

use super::contacts::{apply, local_velocity, Block2, Contacts2, Frame2, Target};
use super::coulomb;
use crate::norms::{natural_map_sq, Sums};
use crate::solver::{Ordering, SolveReport, SolverSettings};
use rand::seq::SliceRandom;
use rand::SeedableRng;

/// Fills `order` with the visiting order of this step's contacts (left empty for
/// storage order).
pub fn make_order(order: &mut Vec<u32>, n: usize, s: &SolverSettings, step: u64) {
    order.clear();
    match s.ordering {
        // empty: storage order, visited without indirection
        Ordering::Stored => {}
        Ordering::Reversed => order.extend((0..n as u32).rev()),
        Ordering::Shuffled => {
            order.extend(0..n as u32);
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(s.seed ^ step.wrapping_mul(0x9E37_79B9_7F4A_7C15));
            order.shuffle(&mut rng);
        }
    }
}

/// The contact fields a sweep reads, sliced to one length so that indexing them
/// in storage order needs no bounds checks.
struct Hot<'a> {
    bodies: &'a [[u32; 2]],
    frame: &'a [Frame2],
    block: &'a [Block2],
    target: &'a [Target],
    r: &'a mut [[f64; 2]],
}

/// One NLGS sweep; accumulates the check sums when `sums` is given. An empty
/// `order` means storage order.
#[inline(never)]
pub fn sweep(c: &mut Contacts2, vel: &mut [[f64; 3]], inv_mass: &[[f64; 3]], order: &[u32], omega: f64, mut sums: Option<&mut Sums>) {
    let m = c.len();
    let mut h = Hot {
        bodies: &c.bodies[..m],
        frame: &c.frame[..m],
        block: &c.block[..m],
        target: &c.target[..m],
        r: &mut c.r[..m],
    };
    // one monomorphized loop per case, so that the plain sweep carries no check or
    // relaxation code (fewer live values, no spills)
    match (sums.as_deref_mut(), omega != 1.0) {
        (None, false) => run::<false, false>(&mut h, order, vel, inv_mass, omega, &mut Sums::default()),
        (None, true) => run::<false, true>(&mut h, order, vel, inv_mass, omega, &mut Sums::default()),
        (Some(s), false) => run::<true, false>(&mut h, order, vel, inv_mass, omega, s),
        (Some(s), true) => run::<true, true>(&mut h, order, vel, inv_mass, omega, s),
    }
}

#[inline(always)]
fn run<const CHECK: bool, const RELAX: bool>(
    h: &mut Hot<'_>,
    order: &[u32],
    vel: &mut [[f64; 3]],
    inv_mass: &[[f64; 3]],
    omega: f64,
    sums: &mut Sums,
) {
    if order.is_empty() {
        for a in 0..h.bodies.len() {
            visit::<CHECK, RELAX>(h, a, vel, inv_mass, omega, sums);
        }
    } else {
        for &a in order {
            visit::<CHECK, RELAX>(h, a as usize, vel, inv_mass, omega, sums);
        }
    }
}

/// Solves contact α with the others' impulses fixed and updates its two bodies:
/// u = H_αᵀ V, u0 = u − W_αα r_α, r_α ← local solution, V += M̂⁻¹ H_α Δr_α.
#[inline(always)]
fn visit<const CHECK: bool, const RELAX: bool>(
    h: &mut Hot<'_>,
    a: usize,
    vel: &mut [[f64; 3]],
    inv_mass: &[[f64; 3]],
    omega: f64,
    sums: &mut Sums,
) {
    let [bi, bj] = h.bodies[a];
    let (bi, bj) = (bi as usize, bj as usize);
    let f = h.frame[a];
    let u = local_velocity(&f, vel[bi], vel[bj]);
    let r = h.r[a];
    let Block2 { w, pre } = h.block[a];
    let wr_old = [w[0] * r[0] + w[1] * r[1], w[1] * r[0] + w[2] * r[1]];
    let u0 = [u[0] - wr_old[0], u[1] - wr_old[1]];
    let t = h.target[a];
    let mut rn = coulomb::solve_pre(w, &pre, u0, t.u_target, t.mu);
    if RELAX {
        rn = [omega * rn[0] + (1.0 - omega) * r[0], omega * rn[1] + (1.0 - omega) * r[1]];
    }
    let dr = [rn[0] - r[0], rn[1] - r[1]];
    if CHECK {
        let wr = [w[0] * rn[0] + w[1] * rn[1], w[1] * rn[0] + w[2] * rn[1]];
        let du = [wr[0] - wr_old[0], wr[1] - wr_old[1]];
        sums.add(&r, &rn, &du, &wr_old, &wr);
    }
    if dr[0] != 0.0 || dr[1] != 0.0 {
        h.r[a] = rn;
        apply(&f, dr, bi, bj, vel, inv_mass);
    }
}

/// Runs sweeps until the criterion holds or `max_sweeps` is reached.
pub fn solve(c: &mut Contacts2, vel: &mut [[f64; 3]], inv_mass: &[[f64; 3]], order: &[u32], s: &SolverSettings) -> SolveReport {
    if c.is_empty() {
        return SolveReport {
            converged: true,
            ..Default::default()
        };
    }
    let mut report = s.run_sweeps(|sums| sweep(c, vel, inv_mass, order, s.relaxation, sums));
    report.residual = residual(c, vel);
    report
}

/// Natural-map residual ‖F(r)‖/‖q‖ of the step's problem, with the normal velocity
/// shifted by the law's target (u_n − ū) and q the shifted free velocity.
pub fn residual(c: &Contacts2, vel: &[[f64; 3]]) -> f64 {
    let (f2, q2) = residual_parts(c, vel);
    if q2 == 0.0 {
        f2.sqrt()
    } else {
        (f2 / q2).sqrt()
    }
}

/// The squared sums (‖F(r)‖², ‖q‖²) of [`residual`], for problems that add other
/// contacts to these.
pub fn residual_parts(c: &Contacts2, vel: &[[f64; 3]]) -> (f64, f64) {
    let mut f2 = 0.0;
    let mut q2 = 0.0;
    for a in 0..c.len() {
        let t = c.target[a];
        let mut u = c.local_velocity(a, vel);
        u[0] -= t.u_target;
        f2 += natural_map_sq(&c.r[a], &u, t.mu);
        let q = [c.u_free[a][0] - t.u_target, c.u_free[a][1]];
        q2 += q[0] * q[0] + q[1] * q[1];
    }
    (f2, q2)
}
