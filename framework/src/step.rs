//! The stages of a Moreau–Jean step that every dimension shares, generic over
//! [`Dim`]:
//!
//! ```text
//! q⁺ = q⁻ + h ((1 − θ) V⁻ + θ V⁺)        integrate (Dim::integrate)
//! reaction_b = Σ_α ±H_b r_α              reactions (N·s, per body)
//! ```

use crate::dim::{Dim, Vector};
use crate::drive::DofDrive;
use crate::model::{all_free, Bodies, Contacts};

pub use crate::error::Diverged;

impl Diverged {
    /// Body k (a slot of `b`; global id `global`, labelled `label`) has a
    /// non-finite state after step `step`.
    pub fn non_finite<D: Dim>(step: u64, (k, global): (usize, u32), label: String, b: &Bodies<D>) -> Diverged {
        Diverged {
            step,
            body: global,
            message: format!(
                "{label} has a non-finite or diverging state (position {:?}, velocity {:?})",
                b.pos[k], b.vel[k]
            ),
        }
    }
}

/// A position (m) or velocity (m/s, rad/s) beyond this has diverged: no scene of the
/// field comes near it, and its squares (energies, norms) would overflow.
pub const DIVERGED: f64 = 1e100;

/// The θ-method's position update of every body from V⁻ (`v_begin`) and V⁺ (the
/// bodies' velocities). Stops at the first body whose state is not finite (or
/// beyond [`DIVERGED`]) and returns its id (the bodies before it are updated).
pub fn integrate<D: Dim>(b: &mut Bodies<D>, v_begin: &[D::Twist], h: f64, theta: f64) -> Result<(), usize> {
    integrate_some(b, v_begin, h, theta, None)
}

/// [`integrate`] of the bodies `only` (ascending ids; `None`: every body).
pub fn integrate_some<D: Dim>(b: &mut Bodies<D>, v_begin: &[D::Twist], h: f64, theta: f64, only: Option<&[u32]>) -> Result<(), usize> {
    let n = b.pos.len();
    let (pos, rot, vel) = (&mut b.pos, &mut b.rot, &b.vel);
    let mut one = |k: usize| {
        D::integrate(&mut pos[k], &mut rot[k], &v_begin[k], &vel[k], h, theta);
        let finite = pos[k].as_ref().iter().chain(vel[k].as_ref()).all(|x| x.abs() < DIVERGED) && D::rot_finite(&rot[k]);
        if finite {
            Ok(())
        } else {
            Err(k)
        }
    };
    match only {
        Some(list) => list.iter().try_for_each(|&k| one(k as usize)),
        None => (0..n).try_for_each(one),
    }
}

/// Calls `f` on every body id of `only` (ascending), or on 0..n when `None`.
#[inline]
pub fn each_body(n: usize, only: Option<&[u32]>, mut f: impl FnMut(usize)) {
    match only {
        Some(list) => list.iter().for_each(|&k| f(k as usize)),
        None => (0..n).for_each(f),
    }
}

/// The contact impulses' resultant on every body, Σ ±H r (N·s; force, then moment).
pub fn reactions<D: Dim>(c: &Contacts<D>, n_bodies: usize, reaction: &mut Vec<D::Twist>) {
    reaction.clear();
    reaction.resize(n_bodies, D::Twist::zero());
    add_reactions(c, reaction);
}

/// Adds Σ ±H r of the contacts `c` to `reaction` (indexed by the contacts' body ids),
/// in storage order.
pub fn add_reactions<D: Dim>(c: &Contacts<D>, reaction: &mut [D::Twist]) {
    for a in 0..c.len() {
        let [i, j] = c.bodies[a];
        let (f, r) = (&c.frame[a], &c.r[a]);
        let (pi, pj) = (D::reaction_i(f, r), D::reaction_j(f, r));
        for k in 0..D::DOF {
            reaction[i as usize][k] += pi[k];
            reaction[j as usize][k] -= pj[k];
        }
    }
}

/// The free degrees of freedom of body k at the end of the step (`t_end`): those
/// not driven by an imposed velocity then (drives `dof`, one per degree of
/// freedom); M̂⁻¹ is recomputed when they change.
pub fn drive_free_dofs<D: Dim>(b: &mut Bodies<D>, k: usize, dof: &[Option<DofDrive>], t_end: f64) {
    let mut free = all_free::<D>();
    for (d, drv) in dof.iter().enumerate() {
        if drv.as_ref().is_some_and(|x| x.is_velocity_at(t_end)) {
            free &= !(1 << d);
        }
    }
    if b.free[k] != free {
        b.free[k] = free;
        b.refresh_inverse(k);
    }
}
