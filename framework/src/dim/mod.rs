//! The dimension: everything that differs between 2D and 3D rigid bodies, in one
//! small trait, so that the rest of the core (contact set, NLGS, NSCDD, …) is
//! written once, generic over `D: Dim` and monomorphized (no dispatch per contact).
//!
//! | symbol (DESIGN.md §2) | [`D2`] | [`D3`] |
//! |---|---|---|
//! | point x, normal n | `[f64; 2]` | `[f64; 3]` |
//! | orientation | angle (rad) | unit quaternion (w, x, y, z) |
//! | twist V (generalized velocity) | (v_x, v_y, ω) | (v, ω), ω in the world frame |
//! | local vector u, r | (n, t) | (n, t1, t2) |
//! | frame | n and the lever arms (d × n, d × t) | basis [n t1 t2] and lever arms d |
//! | W_αα | `[W_nn, W_nt, W_tt]` | upper triangle of a symmetric 3 × 3 |
//! | M̂⁻¹ of a body | diagonal (m⁻¹, m⁻¹, I⁻¹) | diag(m⁻¹) and the world I⁻¹ |
//!
//! A frame's normal points from the antagonist body j towards the candidate i; an
//! impulse r acts as `+H_i r` on i and `−H_j r` on j:
//!
//! ```text
//! u_α = H_iᵀ V_i − H_jᵀ V_j          (Dim::local_velocity)
//! V_i += M̂_i⁻¹ H_i Δr,  V_j −= M̂_j⁻¹ H_j Δr   (Dim::apply)
//! W_αα = H_iᵀ M̂_i⁻¹ H_i + H_jᵀ M̂_j⁻¹ H_j       (Dim::delassus)
//! ```
//!
//! and the one-contact Signorini–Coulomb solver ([`Dim::solve`]) is exact in both
//! dimensions: an enumeration of the cone's faces in 2D ([`coulomb2`]), the 3D
//! solver of [`coulomb3`] (different mathematics, kept apart), both with the
//! bonded mortar joints of [`joint`].
//!
//! ```
//! use nscdd::dim::{Dim, D2, D3};
//! fn dofs<D: Dim>() -> usize { D::DOF }
//! assert_eq!((dofs::<D2>(), dofs::<D3>()), (3, 6));
//! ```

pub mod coulomb2;
pub mod coulomb3;
#[cfg(test)]
mod coulomb3_tests;
pub mod d2;
pub mod d3;
pub mod joint;
pub mod rotation;

pub use d2::D2;
pub use d3::D3;

use joint::Joint;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::fmt::Debug;

/// Plain data that the core stores, copies, sends between threads and writes.
pub trait Pod: Copy + Default + Debug + PartialEq + Send + Sync + Serialize + DeserializeOwned + 'static {}
impl<T: Copy + Default + Debug + PartialEq + Send + Sync + Serialize + DeserializeOwned + 'static> Pod for T {}

/// A small fixed-size vector of `f64` (a point, a twist, a local vector).
pub trait Vector: Pod + AsRef<[f64]> + AsMut<[f64]> + std::ops::Index<usize, Output = f64> + std::ops::IndexMut<usize> {
    const LEN: usize;
    fn from_fn(f: impl FnMut(usize) -> f64) -> Self;
    #[inline(always)]
    fn zero() -> Self {
        Self::from_fn(|_| 0.0)
    }
    /// self − o.
    #[inline(always)]
    fn sub(&self, o: &Self) -> Self {
        Self::from_fn(|k| self[k] - o[k])
    }
    /// Whether every component is 0.
    #[inline(always)]
    fn is_zero(&self) -> bool {
        self.as_ref().iter().all(|&x| x == 0.0)
    }
    #[inline(always)]
    fn dot(&self, o: &Self) -> f64 {
        let mut s = self[0] * o[0];
        for k in 1..Self::LEN {
            s += self[k] * o[k];
        }
        s
    }
}

macro_rules! vector {
    ($($n:literal)*) => {$(
        impl Vector for [f64; $n] {
            const LEN: usize = $n;
            #[inline(always)]
            fn from_fn(f: impl FnMut(usize) -> f64) -> Self {
                std::array::from_fn(f)
            }
        }
    )*};
}
vector!(2 3 4 6);

/// The components of a small value as a slice (a rotation vector, an angle).
pub trait Coords {
    fn coords(&self) -> &[f64];
    fn coords_mut(&mut self) -> &mut [f64];
}
impl Coords for f64 {
    fn coords(&self) -> &[f64] {
        std::slice::from_ref(self)
    }
    fn coords_mut(&mut self) -> &mut [f64] {
        std::slice::from_mut(self)
    }
}
impl<const N: usize> Coords for [f64; N] {
    fn coords(&self) -> &[f64] {
        self
    }
    fn coords_mut(&mut self) -> &mut [f64] {
        self
    }
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::D2 {}
    impl Sealed for super::D3 {}
}

/// What differs between 2D and 3D rigid bodies and their contacts (module docs).
/// Sealed: the two dimensions are [`D2`] and [`D3`].
pub trait Dim: sealed::Sealed + Copy + Default + Debug + PartialEq + Send + Sync + 'static {
    /// Space dimension (2 or 3).
    const N: usize;
    /// Degrees of freedom of a rigid body (3 or 6).
    const DOF: usize;
    /// "2D" or "3D", for messages.
    const NAME: &'static str;
    /// A point or a vector of space.
    type Point: Vector;
    /// A body's orientation (its coordinates: the angle in 2D, the quaternion's
    /// four in 3D).
    type Rot: Pod + Coords;
    /// A body's generalized velocity V (and an impulse on it).
    type Twist: Vector;
    /// A local contact vector (normal first): u, r.
    type Local: Vector;
    /// A contact's frame and lever arms.
    type Frame: Pod;
    /// A Delassus block W_αα.
    type W: Pod;
    /// W_αα with what the local solver precomputes once per step.
    type Block: Pod;
    /// M̂⁻¹ of one body as the solver reads it.
    type InvMass: Pod;
    /// A body's rotational inertia: I about the centre in 2D, the principal
    /// moments (body frame) in 3D.
    type Inertia: Pod + Coords;
    /// A rotation as a vector, as scene files give it: the angle (rad) in 2D, the
    /// rotation vector (axis × angle) in 3D.
    type RotVec: Pod + Coords;

    /// The identity orientation.
    fn rot_identity() -> Self::Rot;
    /// The orientation of a rotation vector.
    fn rot_from_vec(r: &Self::RotVec) -> Self::Rot;
    /// The rotation vector of an orientation.
    fn rot_to_vec(r: &Self::Rot) -> Self::RotVec;
    /// `r p`: a body-frame vector in the world frame.
    fn rotate(r: &Self::Rot, p: &Self::Point) -> Self::Point;
    /// `a ∘ b`: the rotation b, then a.
    fn rot_mul(a: &Self::Rot, b: &Self::Rot) -> Self::Rot;
    /// A valid orientation close to `r` (3D: the quaternion normalised).
    fn normalize_rot(r: Self::Rot) -> Self::Rot;
    /// M̂⁻¹ of a body of mass m and inertia I at orientation `rot`, restricted to the
    /// free degrees of freedom (bit k of `free`: dof k moves under impulses).
    fn inv_mass(mass: f64, inertia: &Self::Inertia, rot: &Self::Rot, free: u8) -> Self::InvMass;
    /// Numbers of M̂⁻¹ as [`Dim::inv_mass_coords`] writes them (3 in 2D, 9 in 3D).
    const INV_MASS_LEN: usize;
    /// M̂⁻¹'s numbers appended to `out`, and back (bit for bit: a body sent between
    /// processes keeps the M̂⁻¹ it has, not one recomputed at its orientation).
    fn inv_mass_coords(im: &Self::InvMass, out: &mut Vec<f64>);
    fn inv_mass_from(x: &[f64]) -> Self::InvMass;
    /// Whether M̂⁻¹ does not depend on the orientation (2D; isotropic 3D bodies).
    fn isotropic(inertia: &Self::Inertia) -> bool;
    /// ρ² = I/m (3D: tr(I)/3m), 0 when undefined: the weight of rotations in the
    /// gluing norm |V|² = |v|² + ρ² |ω|².
    fn rho2(mass: f64, inertia: &Self::Inertia) -> f64;
    /// The θ-method's position update `q⁺ = q⁻ + h((1 − θ)V⁻ + θV⁺)` (3D: the
    /// rotation increment applied as an exact rotation).
    fn integrate(pos: &mut Self::Point, rot: &mut Self::Rot, v0: &Self::Twist, v1: &Self::Twist, h: f64, theta: f64);
    /// ½ Vᵀ M V of a body.
    fn kinetic_energy(mass: f64, inertia: &Self::Inertia, rot: &Self::Rot, v: &Self::Twist) -> f64;
    /// The free-flight increment of a movable body's velocity over a step:
    /// `h M̂⁻¹ m g` on its translations and, in 3D, the explicit gyroscopic torque
    /// `−ω × (I_w ω)` of a body whose inertia is not isotropic.
    #[allow(clippy::too_many_arguments)]
    fn free_flight(v: &mut Self::Twist, mass: f64, inertia: &Self::Inertia, rot: &Self::Rot, inv: &Self::InvMass, g: &Self::Point, h: f64);
    /// An imposed moment's impulse `hm` about the world axis `axis` (2D: the only
    /// one): ω += I⁻¹ hm.
    fn apply_moment(v: &mut Self::Twist, inertia: &Self::Inertia, inv: &Self::InvMass, axis: usize, hm: f64);
    /// Whether an orientation is finite.
    fn rot_finite(r: &Self::Rot) -> bool;

    /// The frame of a contact at `point` with unit normal `normal` (from j to i)
    /// between bodies whose centres are `x_i`, `x_j`.
    fn frame(point: &Self::Point, normal: &Self::Point, x_i: &Self::Point, x_j: &Self::Point) -> Self::Frame;
    /// The unit normal of a frame (from j to i).
    fn normal(f: &Self::Frame) -> Self::Point;
    /// A local vector in world axes (`B r`: the impulse on i).
    fn to_world(f: &Self::Frame, r: &Self::Local) -> Self::Point;
    /// u = H_iᵀ V_i − H_jᵀ V_j.
    fn local_velocity(f: &Self::Frame, vi: &Self::Twist, vj: &Self::Twist) -> Self::Local;
    /// V_i += M̂_i⁻¹ H_i Δr, V_j −= M̂_j⁻¹ H_j Δr.
    fn apply(f: &Self::Frame, dr: &Self::Local, i: usize, j: usize, vel: &mut [Self::Twist], inv: &[Self::InvMass]);
    /// W_αα = H_iᵀ M̂_i⁻¹ H_i + H_jᵀ M̂_j⁻¹ H_j.
    fn delassus(f: &Self::Frame, inv_i: &Self::InvMass, inv_j: &Self::InvMass) -> Self::W;
    /// W_nn, the normal entry of a block (a contact with W_nn ≤ 0 moves nothing).
    fn w_nn(w: &Self::W) -> f64;
    /// W + c e_n e_nᵀ: the block of a contact with normal compliance c.
    fn with_compliance(w: Self::W, c: f64) -> Self::W;
    /// The block of W with the local solver's precomputed data for friction μ.
    fn block(w: Self::W, mu: f64) -> Self::Block;
    /// W_αα r.
    fn w_mul(b: &Self::Block, r: &Self::Local) -> Self::Local;
    /// The exact one-contact Signorini–Coulomb solution for `u0 = u − W r` (`prev`:
    /// the contact's current impulse, a starting guess where the solver uses one).
    fn solve(b: &Self::Block, u0: &Self::Local, u_target: f64, mu: f64, prev: &Self::Local) -> Self::Local;
    /// The one-contact solution of a bonded mortar joint ([`joint`]).
    fn solve_joint(b: &Self::Block, u0: &Self::Local, u_target: f64, mu: f64, j: &Joint, prev: &Self::Local) -> Self::Local;
    /// The projection of `z` on a bonded joint's admissible set K_c ([`joint`];
    /// components past the dimension 0).
    fn project_joint(z: &[f64], mu: f64, j: &Joint) -> [f64; 3];
    /// Whether a bonded joint holds on the converged impulse ([`joint::holds`]).
    #[allow(clippy::too_many_arguments)]
    fn joint_holds(b: &Self::Block, r: &Self::Local, u0: &Self::Local, u_target: f64, mu: f64, j: &Joint, tol: f64) -> bool;
    /// |r − P_Kc(r − ũ)|² of a bonded joint, `u` shifted by ū.
    fn joint_natural_map_sq(r: &Self::Local, u: &Self::Local, mu: f64, j: &Joint) -> f64;
    /// The resultant of the impulse r on body i (`H_i r`: force, moment); body j
    /// receives the opposite of its own arm's resultant, [`Dim::reaction_j`].
    fn reaction_i(f: &Self::Frame, r: &Self::Local) -> Self::Twist;
    /// `H_j r` (body j receives its opposite).
    fn reaction_j(f: &Self::Frame, r: &Self::Local) -> Self::Twist;
    /// M̂_E⁻¹ = m M̂⁻¹ (partition of unity over m copies).
    fn scale_inv(inv: &Self::InvMass, m: f64) -> Self::InvMass;
    /// v += M̂⁻¹ f.
    fn apply_inv(v: &mut Self::Twist, inv: &Self::InvMass, f: &Self::Twist);
    /// The gluing increment of a copy: it moves by `dv` on its free degrees of
    /// freedom and its interface impulse F_Γ grows by M̂_E dv.
    fn glue(v: &mut Self::Twist, f_gamma: &mut Self::Twist, inv: &Self::InvMass, dv: &Self::Twist);
}
