//! The stages of a Moreau–Jean step that every dimension shares, generic over
//! [`Dim`]:
//!
//! ```text
//! q⁺ = q⁻ + h ((1 − θ) V⁻ + θ V⁺)        integrate (Dim::integrate)
//! reaction_b = Σ_α ±H_b r_α              reactions (N·s, per body)
//! ```

use crate::dim::{Dim, Vector};
use crate::model::{Bodies, Contacts};

/// The θ-method's position update of every body from V⁻ (`v_begin`) and V⁺ (the
/// bodies' velocities). Stops at the first body whose state is not finite and
/// returns its id (the bodies before it are updated).
pub fn integrate<D: Dim>(b: &mut Bodies<D>, v_begin: &[D::Twist], h: f64, theta: f64) -> Result<(), usize> {
    for k in 0..b.len() {
        D::integrate(&mut b.pos[k], &mut b.rot[k], &v_begin[k], &b.vel[k], h, theta);
        let finite = b.pos[k].as_ref().iter().chain(b.vel[k].as_ref()).all(|x| x.is_finite()) && D::rot_finite(&b.rot[k]);
        if !finite {
            return Err(k);
        }
    }
    Ok(())
}

/// The contact impulses' resultant on every body, Σ ±H r (N·s; force, then moment).
pub fn reactions<D: Dim>(c: &Contacts<D>, n_bodies: usize, reaction: &mut Vec<D::Twist>) {
    reaction.clear();
    reaction.resize(n_bodies, D::Twist::zero());
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
