//! Non-linear Gauss–Seidel (NLGS) over a contact set of any dimension.
//!
//! One sweep visits the contacts in the chosen order; for contact α it forms the
//! current local velocity `u_α = H_αᵀ V` from the body velocities, removes its own
//! contribution `u0 = u_α − W_αα r_α`, solves the one-contact problem exactly
//! ([`Dim::solve`], or [`Dim::solve_joint`] for a bonded mortar joint), relaxes
//! `r ← ω r_new + (1 − ω) r_old`, and updates the two bodies:
//! `V += M̂⁻¹ H_α Δr_α`. Every `check_every` sweeps the sweep is also a check pass
//! (see [`crate::norms`]). The loop holds only slices of plain data: no allocation
//! and no dynamic dispatch per contact; one monomorphized loop per (check pass,
//! relaxation, joints) case, so that the plain sweep carries no code it does not
//! run (fewer live values, no spills).
//!
//! ```
//! use nscdd::dim::{Dim, D2};
//! use nscdd::model::{Contacts, Target};
//! use nscdd::solver::{nlgs, SolverSettings};
//! // a unit disk resting on a fixed one, pulled down at 1 m/s: W = 1, u_free = −1
//! let inv = [[1.0, 1.0, 1.0], [0.0; 3]];
//! let mut vel = vec![[0.0, -1.0, 0.0], [0.0; 3]];
//! let mut c = Contacts::<D2>::default();
//! let f = D2::frame(&[0.0, 0.0], &[0.0, 1.0], &[0.0, 1.0], &[0.0, -1.0]);
//! c.bodies.push([0, 1]);
//! c.frame.push(f);
//! c.block.push(D2::block(D2::delassus(&f, &inv[0], &inv[1]), 0.5));
//! c.target.push(Target { u_target: 0.0, mu: 0.5 });
//! c.r.push([0.0; 2]);
//! c.u_free.push([-1.0, 0.0]);
//! c.gap.push(0.0);
//! c.point.push([0.0; 2]);
//! c.key.push(nscdd::model::ContactKey { i: 0, j: 1, feature: 0 });
//! c.joint.push(Default::default());
//! let report = nlgs::solve(&mut c, &mut vel, &inv, &[], &SolverSettings::default());
//! assert!(report.converged && c.r[0] == [1.0, 0.0] && vel[0] == [0.0; 3]);
//! ```

use super::{Ordering, SolveReport, SolverSettings};
use crate::dim::joint::Joint;
use crate::dim::{Dim, Vector};
use crate::model::{Contacts, Target};
use crate::norms::{natural_map_sq, Sums};
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
struct Hot<'a, D: Dim> {
    bodies: &'a [[u32; 2]],
    frame: &'a [D::Frame],
    block: &'a [D::Block],
    target: &'a [Target],
    r: &'a mut [D::Local],
    joint: &'a [Joint],
}

/// One NLGS sweep; accumulates the check sums when `sums` is given. An empty
/// `order` means storage order.
#[inline(never)]
pub fn sweep<D: Dim>(c: &mut Contacts<D>, vel: &mut [D::Twist], inv: &[D::InvMass], order: &[u32], omega: f64, sums: Option<&mut Sums>) {
    let joints = c.any_bonded();
    let m = c.len();
    let mut h = Hot::<D> {
        bodies: &c.bodies[..m],
        frame: &c.frame[..m],
        block: &c.block[..m],
        target: &c.target[..m],
        r: &mut c.r[..m],
        joint: &c.joint[..m],
    };
    let relax = omega != 1.0;
    let mut none = Sums::default();
    macro_rules! go {
        ($check:literal, $s:expr) => {
            match (relax, joints) {
                (false, false) => run::<D, $check, false, false>(&mut h, order, vel, inv, omega, $s),
                (true, false) => run::<D, $check, true, false>(&mut h, order, vel, inv, omega, $s),
                (false, true) => run::<D, $check, false, true>(&mut h, order, vel, inv, omega, $s),
                (true, true) => run::<D, $check, true, true>(&mut h, order, vel, inv, omega, $s),
            }
        };
    }
    match sums {
        None => go!(false, &mut none),
        Some(s) => go!(true, s),
    }
}

#[inline(always)]
fn run<D: Dim, const CHECK: bool, const RELAX: bool, const JOINTS: bool>(
    h: &mut Hot<'_, D>,
    order: &[u32],
    vel: &mut [D::Twist],
    inv: &[D::InvMass],
    omega: f64,
    sums: &mut Sums,
) {
    if order.is_empty() {
        for a in 0..h.bodies.len() {
            visit::<D, CHECK, RELAX, JOINTS>(h, a, vel, inv, omega, sums);
        }
    } else {
        for &a in order {
            visit::<D, CHECK, RELAX, JOINTS>(h, a as usize, vel, inv, omega, sums);
        }
    }
}

/// Solves contact α with the others' impulses fixed and updates its two bodies:
/// u = H_αᵀ V, u0 = u − W_αα r_α, r_α ← local solution, V += M̂⁻¹ H_α Δr_α.
#[inline(always)]
fn visit<D: Dim, const CHECK: bool, const RELAX: bool, const JOINTS: bool>(
    h: &mut Hot<'_, D>,
    a: usize,
    vel: &mut [D::Twist],
    inv: &[D::InvMass],
    omega: f64,
    sums: &mut Sums,
) {
    let [bi, bj] = h.bodies[a];
    let (bi, bj) = (bi as usize, bj as usize);
    let f = &h.frame[a];
    let u = D::local_velocity(f, &vel[bi], &vel[bj]);
    let r = h.r[a];
    let blk = &h.block[a];
    let wr_old = D::w_mul(blk, &r);
    let u0 = u.sub(&wr_old);
    let t = h.target[a];
    let mut rn = if JOINTS && h.joint[a].bonded() {
        D::solve_joint(blk, &u0, t.u_target, t.mu, &h.joint[a], &r)
    } else {
        D::solve(blk, &u0, t.u_target, t.mu, &r)
    };
    if RELAX {
        rn = D::Local::from_fn(|k| omega * rn[k] + (1.0 - omega) * r[k]);
    }
    let dr = rn.sub(&r);
    if CHECK {
        let wr = D::w_mul(blk, &rn);
        let du = wr.sub(&wr_old);
        sums.add(r.as_ref(), rn.as_ref(), du.as_ref(), wr_old.as_ref(), wr.as_ref());
    }
    if !dr.is_zero() {
        h.r[a] = rn;
        D::apply(f, &dr, bi, bj, vel, inv);
    }
}

/// Runs sweeps until the criterion holds or `max_sweeps` is reached.
pub fn solve<D: Dim>(c: &mut Contacts<D>, vel: &mut [D::Twist], inv: &[D::InvMass], order: &[u32], s: &SolverSettings) -> SolveReport {
    if c.is_empty() {
        return SolveReport {
            converged: true,
            ..Default::default()
        };
    }
    let mut report = s.run_sweeps(|sums| sweep(c, vel, inv, order, s.relaxation, sums));
    report.residual = residual(c, vel);
    report
}

/// Natural-map residual ‖F(r)‖/‖q‖ of the step's problem, with the normal velocity
/// shifted by the law's target (u_n − ū) and q the shifted free velocity.
pub fn residual<D: Dim>(c: &Contacts<D>, vel: &[D::Twist]) -> f64 {
    let (f2, q2) = residual_parts(c, vel);
    residual_of(f2, q2)
}

/// ‖F(r)‖/‖q‖ from the squared sums of [`residual_parts`] (added over the problems
/// that make up a step): ‖F(r)‖ alone when q vanishes.
pub fn residual_of(f2: f64, q2: f64) -> f64 {
    if q2 == 0.0 {
        f2.sqrt()
    } else {
        (f2 / q2).sqrt()
    }
}

/// The squared sums (‖F(r)‖², ‖q‖²) of [`residual`], for problems that add other
/// contacts to these.
pub fn residual_parts<D: Dim>(c: &Contacts<D>, vel: &[D::Twist]) -> (f64, f64) {
    let (mut f2, mut q2) = (0.0, 0.0);
    for a in 0..c.len() {
        let t = c.target[a];
        let mut u = c.local_velocity(a, vel);
        u[0] -= t.u_target;
        let jt = c.joint[a];
        f2 += if jt.bonded() {
            D::joint_natural_map_sq(&c.r[a], &u, t.mu, &jt)
        } else {
            natural_map_sq(c.r[a].as_ref(), u.as_ref(), t.mu)
        };
        let mut q = c.u_free[a];
        q[0] -= t.u_target;
        q2 += q.dot(&q);
    }
    (f2, q2)
}
