//! Struct-of-arrays storage of 2D rigid bodies, indexed by dense `u32` ids.

use serde::{Deserialize, Serialize};

/// Where a body's geometry lives: shape kind id (index in the scene's shape table)
/// and the index of the shape inside that kind's store.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct ShapeRef {
    pub kind: u16,
    pub index: u32,
}

/// 2D rigid bodies. One `Vec` per field; `vel` and `inv_mass` are the hot fields of
/// the contact solver.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Bodies2 {
    /// Centre of mass.
    pub pos: Vec<[f64; 2]>,
    /// Rotation angle (rad).
    pub rot: Vec<f64>,
    /// Current velocity V = (v_x, v_y, ω); V⁻ at the start of a step, V⁺ after it.
    pub vel: Vec<[f64; 3]>,
    /// Diagonal of M̂ = diag(m, m, I).
    pub mass: Vec<[f64; 3]>,
    /// Diagonal of M̂⁻¹ restricted to the free degrees of freedom (0 where driven by
    /// velocity or fixed).
    pub inv_mass: Vec<[f64; 3]>,
    /// Area (2D volume per unit depth), for the solid fraction.
    pub area: Vec<f64>,
    pub shape: Vec<ShapeRef>,
    pub material: Vec<u16>,
    /// Index into the scene's drives, or `u32::MAX`.
    pub drive: Vec<u32>,
}

impl Bodies2 {
    pub fn len(&self) -> usize {
        self.pos.len()
    }
    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        pos: [f64; 2],
        rot: f64,
        vel: [f64; 3],
        mass: f64,
        inertia: f64,
        area: f64,
        shape: ShapeRef,
        material: u16,
    ) -> u32 {
        let id = self.pos.len() as u32;
        self.pos.push(pos);
        self.rot.push(rot);
        self.vel.push(vel);
        self.mass.push([mass, mass, inertia]);
        self.inv_mass.push([1.0 / mass, 1.0 / mass, 1.0 / inertia]);
        self.area.push(area);
        self.shape.push(shape);
        self.material.push(material);
        self.drive.push(u32::MAX);
        id
    }

    /// ρ² = I/m (0 when undefined): the weight of rotations in the gluing norm
    /// |V|² = |v|² + ρ² |ω|².
    pub fn rho2(&self, b: usize) -> f64 {
        let ms = self.mass[b];
        if ms[0] > 0.0 && ms[0].is_finite() && ms[2].is_finite() {
            ms[2] / ms[0]
        } else {
            0.0
        }
    }

    /// Whether contact impulses can move the body at all.
    #[inline]
    pub fn movable(&self, b: usize) -> bool {
        self.inv_mass[b].iter().any(|&x| x != 0.0)
    }
}
