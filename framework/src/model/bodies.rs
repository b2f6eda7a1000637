//! Struct-of-arrays storage of rigid bodies of any dimension, indexed by dense `u32`
//! ids. `vel` and `inv_mass` are the contact solver's hot fields; the solver sees a
//! body only through them (its twist and M̂⁻¹, [`crate::dim::Dim`]).

use crate::dim::Dim;
use serde::{Deserialize, Serialize};

/// Where a body's geometry lives: shape kind id (index in the scene's shape table)
/// and the index of the shape inside that kind's store.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct ShapeRef {
    pub kind: u16,
    pub index: u32,
}

/// Every degree of freedom of a `D` body free (bit k: dof k moves under impulses).
pub const fn all_free<D: Dim>() -> u8 {
    ((1u16 << D::DOF) - 1) as u8
}

/// Rigid bodies.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(bound = "")]
pub struct Bodies<D: Dim> {
    /// Centre of mass.
    pub pos: Vec<D::Point>,
    /// Orientation: angle (rad) in 2D, unit quaternion (w, x, y, z) body → world in 3D.
    pub rot: Vec<D::Rot>,
    /// Twist V: V⁻ at the start of a step, V⁺ after it.
    pub vel: Vec<D::Twist>,
    pub mass: Vec<f64>,
    /// I about the centre (2D), principal moments in the body frame (3D).
    pub inertia: Vec<D::Inertia>,
    /// M̂⁻¹ restricted to the free degrees of freedom (0 where driven by velocity
    /// or fixed).
    pub inv_mass: Vec<D::InvMass>,
    /// Which degrees of freedom are free (bit k: dof k moves under impulses).
    pub free: Vec<u8>,
    /// Volume (2D: area per unit depth), for the solid fraction.
    pub volume: Vec<f64>,
    pub shape: Vec<ShapeRef>,
    pub material: Vec<u16>,
}

impl<D: Dim> Bodies<D> {
    pub fn len(&self) -> usize {
        self.pos.len()
    }
    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        pos: D::Point,
        rot: D::Rot,
        vel: D::Twist,
        mass: f64,
        inertia: D::Inertia,
        volume: f64,
        shape: ShapeRef,
        material: u16,
    ) -> u32 {
        let id = self.pos.len() as u32;
        let rot = D::normalize_rot(rot);
        self.pos.push(pos);
        self.rot.push(rot);
        self.vel.push(vel);
        self.mass.push(mass);
        self.inertia.push(inertia);
        self.inv_mass.push(D::inv_mass(mass, &inertia, &rot, all_free::<D>()));
        self.free.push(all_free::<D>());
        self.volume.push(volume);
        self.shape.push(shape);
        self.material.push(material);
        id
    }

    /// Fixes body b: no degree of freedom moves.
    pub fn set_fixed(&mut self, b: usize) {
        self.free[b] = 0;
        self.refresh_inverse(b);
    }

    /// Recomputes M̂⁻¹ of body b from its mass, orientation and free degrees of
    /// freedom.
    pub fn refresh_inverse(&mut self, b: usize) {
        self.inv_mass[b] = D::inv_mass(self.mass[b], &self.inertia[b], &self.rot[b], self.free[b]);
    }

    /// ρ² = I/m (0 when undefined): the weight of rotations in the gluing norm.
    pub fn rho2(&self, b: usize) -> f64 {
        D::rho2(self.mass[b], &self.inertia[b])
    }

    /// Whether contact impulses can move the body at all.
    #[inline]
    pub fn movable(&self, b: usize) -> bool {
        self.free[b] != 0
    }
}
