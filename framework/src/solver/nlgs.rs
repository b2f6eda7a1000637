//! Non-linear Gauss–Seidel (NLGS) over a contact set of any dimension.
//!
//! One sweep visits the contacts in the chosen order; for contact α it forms the
//! current local velocity `u_α = H_αᵀ V` from the body velocities, removes its own
//! contribution `u0 = u_α − W_αα r_α`, solves the one-contact problem exactly
//! ([`Dim::solve`], or [`Dim::solve_joint`] for a bonded mortar joint), relaxes
//! `r ← ω r_new + (1 − ω) r_old`, and updates the two bodies:
//! `V += M̂⁻¹ H_α Δr_α`. After every `check_every`-th sweep, [`solve`] runs a
//! check pass ([`check_pass`], LMGC90's): each contact's local solution r' with
//! the others as they are, compared with its current r (see [`crate::norms`]),
//! *without* updating anything; NSCDD's rigid subdomains do the same. (A check
//! pass that updates — a sweep that also sums, [`sweep`] with sums — measures the
//! Gauss–Seidel increments instead: on LMGC90's 2000-disk biaxial test its norms
//! read 1.4–1.5× the non-updating ones and NLGS needed 214 sweeps a step instead
//! of 102 over the first 3000 steps, docs/PERFORMANCE.md.) The loop holds only
//! slices of plain data: no allocation and no dynamic dispatch per contact; one
//! monomorphized loop per (check pass, update, relaxation, joints) case, so that
//! the plain sweep carries no code it does not run (fewer live values, no spills).
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
//! let report = nlgs::solve(&mut c, &mut vel, &inv, &mut [], &SolverSettings::default());
//! assert!(report.converged && c.r[0] == [1.0, 0.0] && vel[0] == [0.0; 3]);
//! ```

use super::{Ordering, SolveReport, SolverSettings};
use crate::dim::joint::Joint;
use crate::dim::{Dim, Vector};
use crate::model::{Contacts, Target};
use crate::norms::{natural_map_sq, project_cone, Sums};
use rand::seq::SliceRandom;
use rand::SeedableRng;

/// Fills `order` with the visiting order of this step's contacts (left empty for
/// storage order); `point(a)` is contact a's point in a space of `space`
/// dimensions (read by `sorted` only).
pub fn make_order(order: &mut Vec<u32>, n: usize, s: &SolverSettings, step: u64, space: usize, point: impl Fn(usize) -> [f64; 3]) {
    make_order_of(order, n, s, step, 0, space, point)
}

/// [`make_order`] for part `part` of a step's contacts (NSCDD's subdomain `part`):
/// its own permutation for `shuffled`, seeded by the step and the part (part 0: the
/// one-domain permutation), so that a subdomain's order needs only its own contacts.
#[allow(clippy::too_many_arguments)]
pub fn make_order_of(
    order: &mut Vec<u32>,
    n: usize,
    s: &SolverSettings,
    step: u64,
    part: u64,
    space: usize,
    point: impl Fn(usize) -> [f64; 3],
) {
    order.clear();
    match s.ordering {
        // empty: storage order, visited without indirection
        Ordering::Stored => {}
        Ordering::Reversed => order.extend((0..n as u32).rev()),
        Ordering::Shuffled | Ordering::Scrambled => {
            order.extend(0..n as u32);
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(
                s.seed ^ step.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ part.wrapping_mul(0xC2B2_AE3D_27D4_EB4F),
            );
            order.shuffle(&mut rng);
        }
        Ordering::Sorted => {
            let d = s.sort_axis(space);
            // (+ 0.0: −0 and +0 are one coordinate)
            let along = |a: usize| {
                let p = point(a);
                d[0] * p[0] + d[1] * p[1] + d[2] * p[2] + 0.0
            };
            order.extend(0..n as u32);
            // the coordinate as an integer of the same order (IEEE 754's total order),
            // then storage order: one key, no ties
            order.sort_by_cached_key(|&a| (total_order_bits(along(a as usize)), a));
        }
    }
}

/// An f64's bits as a u64 in the order of the numbers (IEEE 754 total order).
fn total_order_bits(x: f64) -> u64 {
    let b = x.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | (1 << 63)
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
    /// The cold law data, read only on the `COLD` path (empty slices otherwise).
    joint: &'a [Joint],
    compliance: &'a [f64],
}

/// One NLGS sweep; accumulates the check sums when `sums` is given (an updating
/// check, the Gauss–Seidel increments; [`check_pass`] is LMGC90's). An empty
/// `order` means storage order.
pub fn sweep<D: Dim>(c: &mut Contacts<D>, vel: &mut [D::Twist], inv: &[D::InvMass], order: &[u32], omega: f64, sums: Option<&mut Sums>) {
    pass(c, vel, inv, order, omega, sums, true)
}

/// LMGC90's check pass: the check sums of every contact's local solution with the
/// others as they are, nothing updated. The solution is not relaxed (as in
/// LMGC90's `solve_nlgs(i_check)`): with ω < 1 the sums measure the distance to
/// the local solutions, not the relaxed step towards them.
pub fn check_pass<D: Dim>(c: &mut Contacts<D>, vel: &mut [D::Twist], inv: &[D::InvMass], order: &[u32], sums: &mut Sums) {
    pass(c, vel, inv, order, 1.0, Some(sums), false)
}

#[inline(never)]
fn pass<D: Dim>(
    c: &mut Contacts<D>,
    vel: &mut [D::Twist],
    inv: &[D::InvMass],
    order: &[u32],
    omega: f64,
    sums: Option<&mut Sums>,
    update: bool,
) {
    // bonded joints or compliant contacts: the path that reads their cold data
    let cold = c.compliant || c.any_bonded();
    let m = c.len();
    let mut h = Hot::<D> {
        bodies: &c.bodies[..m],
        frame: &c.frame[..m],
        block: &c.block[..m],
        target: &c.target[..m],
        r: &mut c.r[..m],
        joint: &c.joint[..m],
        compliance: if cold && c.compliant { &c.compliance[..m] } else { &[] },
    };
    let relax = omega != 1.0;
    let mut none = Sums::default();
    macro_rules! go {
        ($check:literal, $update:literal, $s:expr) => {
            match (relax, cold) {
                (false, false) => run::<D, $check, $update, false, false>(&mut h, order, vel, inv, omega, $s),
                (true, false) => run::<D, $check, $update, true, false>(&mut h, order, vel, inv, omega, $s),
                (false, true) => run::<D, $check, $update, false, true>(&mut h, order, vel, inv, omega, $s),
                (true, true) => run::<D, $check, $update, true, true>(&mut h, order, vel, inv, omega, $s),
            }
        };
    }
    match (sums, update) {
        (None, _) => go!(false, true, &mut none),
        (Some(s), true) => go!(true, true, s),
        (Some(s), false) => go!(true, false, s),
    }
}

#[inline(always)]
fn run<D: Dim, const CHECK: bool, const UPDATE: bool, const RELAX: bool, const COLD: bool>(
    h: &mut Hot<'_, D>,
    order: &[u32],
    vel: &mut [D::Twist],
    inv: &[D::InvMass],
    omega: f64,
    sums: &mut Sums,
) {
    if order.is_empty() {
        for a in 0..h.bodies.len() {
            visit::<D, CHECK, UPDATE, RELAX, COLD>(h, a, vel, inv, omega, sums);
        }
    } else {
        for &a in order {
            visit::<D, CHECK, UPDATE, RELAX, COLD>(h, a as usize, vel, inv, omega, sums);
        }
    }
}

/// Solves contact α with the others' impulses fixed and updates its two bodies:
/// u = H_αᵀ V, u0 = u − W_αα r_α, r_α ← local solution, V += M̂⁻¹ H_α Δr_α (with
/// `UPDATE`; without, only the check sums). With `COLD`, bonded joints take the
/// joint solver and a contact of compliance c, whose block holds W_αα + c e_n e_nᵀ,
/// gets u0 = u − W_αα r_α: the local solution then obeys u_n + c r_n ≥ ū ⊥ r_n ≥ 0.
#[inline(always)]
fn visit<D: Dim, const CHECK: bool, const UPDATE: bool, const RELAX: bool, const COLD: bool>(
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
    let mut u0 = u.sub(&wr_old);
    if COLD && !h.compliance.is_empty() {
        u0.as_mut()[0] += h.compliance[a] * r.as_ref()[0];
    }
    let t = h.target[a];
    let mut rn = if COLD && h.joint[a].bonded() {
        D::solve_joint(blk, &u0, t.u_target, t.mu, &h.joint[a], &r)
    } else {
        D::solve(blk, &u0, t.u_target, t.mu, &r)
    };
    if RELAX {
        let joint = COLD && h.joint[a].bonded();
        super::relax(r.as_ref(), rn.as_mut(), omega, |z| {
            if joint {
                D::project_joint(z, t.mu, &h.joint[a])
            } else {
                project_cone(z, t.mu)
            }
        });
    }
    let dr = rn.sub(&r);
    if CHECK {
        let wr = D::w_mul(blk, &rn);
        let du = wr.sub(&wr_old);
        sums.add(r.as_ref(), rn.as_ref(), du.as_ref(), wr_old.as_ref(), wr.as_ref());
    }
    if UPDATE && !dr.is_zero() {
        h.r[a] = rn;
        D::apply(f, &dr, bi, bj, vel, inv);
    }
}

/// Runs sweeps until the criterion holds or `max_sweeps` is reached, a check pass
/// ([`check_pass`]) after every `check_every`-th sweep.
pub fn solve<D: Dim>(c: &mut Contacts<D>, vel: &mut [D::Twist], inv: &[D::InvMass], order: &mut [u32], s: &SolverSettings) -> SolveReport {
    if c.is_empty() {
        return SolveReport {
            converged: true,
            ..Default::default()
        };
    }
    let (every, mut n) = (s.check_every.max(1), 0u32);
    let mut report = s.run_sweeps(|sums| {
        if s.ordering == Ordering::Scrambled && n > 0 && n % every == 0 {
            // a new permutation for the next block, from the last one
            let block = u64::from(n / every);
            order.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(
                s.seed ^ block.wrapping_mul(0xD1B5_4A32_D192_ED03),
            ));
        }
        n += 1;
        sweep(c, vel, inv, order, s.relaxation, None);
        if let Some(sums) = sums {
            check_pass(c, vel, inv, order, sums);
        }
    });
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
    residual_parts_of(c, vel, 0..c.len())
}

/// [`residual_parts`] over the contacts `which`, summed in that order (NSCDD: one
/// subdomain's, so that the sums can be added in subdomain order whoever holds them).
pub fn residual_parts_of<D: Dim>(c: &Contacts<D>, vel: &[D::Twist], which: impl Iterator<Item = usize>) -> (f64, f64) {
    let (mut f2, mut q2) = (0.0, 0.0);
    for a in which {
        let t = c.target[a];
        let mut u = c.local_velocity(a, vel);
        u[0] -= t.u_target;
        if c.compliant {
            u[0] += c.compliance[a] * c.r[a][0];
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::D2;
    use crate::model::ContactKey;

    /// A column of `n` unit disks on a fixed one, each pulled down at 1 m/s.
    fn column(n: usize) -> (Contacts<D2>, Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let mut inv = vec![[0.0; 3]];
        let mut vel = vec![[0.0; 3]];
        let mut c = Contacts::<D2>::default();
        for k in 0..n {
            inv.push([1.0, 1.0, 1.0]);
            vel.push([0.0, -1.0, 0.0]);
            let (i, j) = (k as u32 + 1, k as u32);
            let y = 2.0 * k as f64 + 1.0;
            let f = D2::frame(&[0.0, y], &[0.0, 1.0], &[0.0, y + 1.0], &[0.0, y - 1.0]);
            c.bodies.push([i, j]);
            c.frame.push(f);
            c.block.push(D2::block(D2::delassus(&f, &inv[i as usize], &inv[j as usize]), 0.5));
            c.target.push(Target { u_target: 0.0, mu: 0.5 });
            c.r.push([0.0; 2]);
            c.u_free.push([0.0; 2]);
            c.gap.push(0.0);
            c.point.push([0.0, y]);
            c.key.push(ContactKey { i, j, feature: 0 });
            c.joint.push(Default::default());
        }
        (c, vel, inv)
    }

    #[test]
    fn a_check_pass_updates_nothing_and_sums_the_local_solutions() {
        let (mut c, mut vel, inv) = column(4);
        sweep(&mut c, &mut vel, &inv, &[], 1.0, None);
        let (r, v) = (c.r.clone(), vel.clone());
        let mut sums = Sums::default();
        check_pass(&mut c, &mut vel, &inv, &[], &mut sums);
        assert_eq!((&c.r, &vel), (&r, &v), "a check pass changes no impulse and no velocity");
        // the sums of each contact's local solution against the state before the
        // pass (a Jacobi pass)
        let mut expected = Sums::default();
        for a in 0..c.len() {
            let u = c.local_velocity(a, &vel);
            let wr_old = D2::w_mul(&c.block[a], &c.r[a]);
            let u0 = u.sub(&wr_old);
            let rn = D2::solve(&c.block[a], &u0, 0.0, 0.5, &c.r[a]);
            let wr = D2::w_mul(&c.block[a], &rn);
            expected.add(&c.r[a], &rn, wr.sub(&wr_old).as_ref(), &wr_old, &wr);
        }
        assert_eq!(format!("{sums:?}"), format!("{expected:?}"));
    }

    /// With ω = ½ a sweep goes half way to the local solutions; the check pass
    /// measures the distance to them, not the relaxed step (LMGC90's i_check), so
    /// a relaxed NLGS does not stop early.
    #[test]
    fn the_check_pass_is_not_relaxed() {
        let (mut c, mut vel, inv) = column(4);
        sweep(&mut c, &mut vel, &inv, &[], 0.5, None);
        let mut sums = Sums::default();
        check_pass(&mut c, &mut vel, &inv, &[], &mut sums);
        let mut expected = Sums::default();
        for a in 0..c.len() {
            let wr_old = D2::w_mul(&c.block[a], &c.r[a]);
            let u0 = c.local_velocity(a, &vel).sub(&wr_old);
            let rn = D2::solve(&c.block[a], &u0, 0.0, 0.5, &c.r[a]);
            let wr = D2::w_mul(&c.block[a], &rn);
            expected.add(&c.r[a], &rn, wr.sub(&wr_old).as_ref(), &wr_old, &wr);
        }
        assert_eq!(format!("{sums:?}"), format!("{expected:?}"));
        assert!(sums.sum_dvdv > 0.0);
    }

    #[test]
    fn sorted_visits_along_the_direction_ties_in_storage_order() {
        let pts = [[0.0, 2.0, 0.0], [5.0, -1.0, 0.0], [1.0, 2.0, 0.0], [-3.0, 0.5, 0.0]];
        let mut s = SolverSettings {
            ordering: Ordering::Sorted,
            ..Default::default()
        };
        let mut order = vec![];
        // none given: the last axis (y in 2D), ties (contacts 0 and 2) in storage order
        make_order(&mut order, 4, &s, 0, 2, |a| pts[a]);
        assert_eq!(order, [1, 3, 0, 2]);
        s.sort_direction = Some(vec![-1.0, 0.0]);
        make_order(&mut order, 4, &s, 0, 2, |a| pts[a]);
        assert_eq!(order, [1, 2, 0, 3]);
        assert!(total_order_bits(-0.0) < total_order_bits(0.0));
        assert!(total_order_bits(-2.0) < total_order_bits(-1.0) && total_order_bits(1.0) < total_order_bits(2.0));
    }

    #[test]
    fn scrambled_and_shuffled_orders_converge_to_the_same_impulses() {
        let solve_with = |ordering| {
            let (mut c, mut vel, inv) = column(30);
            let s = SolverSettings {
                tolerance: 1e-8,
                max_sweeps: 100_000,
                ordering,
                seed: 3,
                ..Default::default()
            };
            let mut order = vec![];
            make_order(&mut order, c.len(), &s, 7, 2, |a| c.point3(a));
            let rep = solve(&mut c, &mut vel, &inv, &mut order, &s);
            assert!(rep.converged, "{ordering:?}: {rep:?}");
            (c.r, rep.sweeps)
        };
        let (a, na) = solve_with(Ordering::Shuffled);
        let (b, nb) = solve_with(Ordering::Scrambled);
        let (b2, nb2) = solve_with(Ordering::Scrambled);
        assert_eq!((&b, nb), (&b2, nb2), "scrambled is deterministic");
        // the column carries k m g: r_n of contact k = (30 − k) × 1
        for (k, (x, y)) in a.iter().zip(&b).enumerate() {
            let exact = (30 - k) as f64;
            assert!(
                (x[0] - exact).abs() < 1e-4 * exact && (y[0] - exact).abs() < 1e-4 * exact,
                "{k}: {x:?} {y:?}"
            );
        }
        println!("sweeps: shuffled {na}, scrambled {nb}");
    }
}
