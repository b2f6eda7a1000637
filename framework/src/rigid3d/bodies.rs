//! Struct-of-arrays storage of 3D rigid bodies, indexed by dense `u32` ids, and the
//! rotation algebra they need.
//!
//! A body's generalized velocity is `V = (v, ω)` with ω in the world frame; its
//! orientation a unit quaternion `q = (w, x, y, z)` mapping body to world
//! coordinates. Its iteration matrix is `M̂ = diag(m I₃, I_w)` with the world inertia
//! `I_w = R diag(I₁, I₂, I₃) Rᵀ` (principal moments in the body frame). The
//! solver sees only `M̂⁻¹`: per-axis translational entries (0 where a degree of
//! freedom is driven by velocity or fixed) and the symmetric world tensor
//! `I_w⁻¹` restricted to the free rotational axes ([`Bodies3::refresh_inverse`]).

use crate::dim::coulomb3::Sym3;
use crate::dim::d3::InvMass3;
pub use crate::dim::d3::{cross, dot};
use crate::rigid2d::bodies::ShapeRef;
use serde::{Deserialize, Serialize};

/// 3D rigid bodies. `vel` and `inv_mass` are the contact solver's hot fields.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Bodies3 {
    pub pos: Vec<[f64; 3]>,
    /// Unit quaternion (w, x, y, z), body → world.
    pub quat: Vec<[f64; 4]>,
    /// V = (v_x, v_y, v_z, ω_x, ω_y, ω_z), ω in the world frame.
    pub vel: Vec<[f64; 6]>,
    pub mass: Vec<f64>,
    /// Principal moments of inertia (body frame).
    pub inertia: Vec<[f64; 3]>,
    /// M̂⁻¹: the translational diagonal (0 on driven or fixed axes) and the
    /// rotational block in the world frame, upper triangle [xx, xy, xz, yy, yz, zz],
    /// restricted to the free rotational axes.
    pub inv_mass: Vec<InvMass3>,
    /// Which of the 6 degrees of freedom are free (bit k: dof k moves under impulses).
    pub free: Vec<u8>,
    pub volume: Vec<f64>,
    pub shape: Vec<ShapeRef>,
    pub material: Vec<u16>,
}

/// All six degrees of freedom free.
pub const ALL_FREE: u8 = 0b11_1111;

impl Bodies3 {
    pub fn len(&self) -> usize {
        self.pos.len()
    }
    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        pos: [f64; 3],
        quat: [f64; 4],
        vel: [f64; 6],
        mass: f64,
        inertia: [f64; 3],
        volume: f64,
        shape: ShapeRef,
        material: u16,
    ) -> u32 {
        let id = self.pos.len() as u32;
        self.pos.push(pos);
        self.quat.push(normalize(quat));
        self.vel.push(vel);
        self.mass.push(mass);
        self.inertia.push(inertia);
        self.inv_mass.push(InvMass3::default());
        self.free.push(ALL_FREE);
        self.volume.push(volume);
        self.shape.push(shape);
        self.material.push(material);
        self.refresh_inverse(id as usize);
        id
    }

    /// ρ² = tr(I)/(3m) (0 when undefined): the weight of rotations in the gluing
    /// norm |V|² = |v|² + ρ² |ω|².
    pub fn rho2(&self, b: usize) -> f64 {
        let (m, i) = (self.mass[b], self.inertia[b]);
        if m > 0.0 && m.is_finite() && i.iter().all(|x| x.is_finite()) {
            (i[0] + i[1] + i[2]) / (3.0 * m)
        } else {
            0.0
        }
    }

    /// Whether contact impulses can move the body at all.
    #[inline]
    pub fn movable(&self, b: usize) -> bool {
        self.free[b] != 0
    }

    /// World inertia tensor I_w = R diag(I) Rᵀ (upper triangle).
    pub fn world_inertia(&self, b: usize) -> Sym3 {
        let r = rotation_matrix(self.quat[b]);
        let i = self.inertia[b];
        let e = |a: usize, c: usize| (0..3).map(|k| r[a][k] * i[k] * r[c][k]).sum::<f64>();
        [e(0, 0), e(0, 1), e(0, 2), e(1, 1), e(1, 2), e(2, 2)]
    }

    /// Recomputes M̂⁻¹ of body b from its mass, orientation and free degrees of
    /// freedom: `inv_m = 1/m` on free axes, `inv_i = (I_w restricted to the free
    /// rotational axes)⁻¹`, padded with zeros.
    pub fn refresh_inverse(&mut self, b: usize) {
        let f = self.free[b];
        let m = self.mass[b];
        for k in 0..3 {
            self.inv_mass[b].m[k] = if f & (1 << k) != 0 { 1.0 / m } else { 0.0 };
        }
        // the free rotational axes, without allocating (this runs every step for
        // bodies whose world inertia turns with them)
        let (mut rot_free, mut nfree) = ([0usize; 3], 0);
        for k in 0..3 {
            if f & (1 << (3 + k)) != 0 {
                rot_free[nfree] = k;
                nfree += 1;
            }
        }
        let iw = self.world_inertia(b);
        // entry (a, c) of the symmetric tensor stored as [xx, xy, xz, yy, yz, zz]
        const IDX: [[usize; 3]; 3] = [[0, 1, 2], [1, 3, 4], [2, 4, 5]];
        let full = |a: usize, c: usize| iw[IDX[a][c]];
        let mut out = [[0.0; 3]; 3];
        match nfree {
            0 => {}
            1 => {
                let a = rot_free[0];
                out[a][a] = 1.0 / full(a, a);
            }
            2 => {
                let (a, c) = (rot_free[0], rot_free[1]);
                let (p, q, s) = (full(a, a), full(a, c), full(c, c));
                let det = p * s - q * q;
                out[a][a] = s / det;
                out[a][c] = -q / det;
                out[c][a] = -q / det;
                out[c][c] = p / det;
            }
            _ => {
                let inv = crate::dim::coulomb3::inverse(&iw).unwrap_or([0.0; 6]);
                self.inv_mass[b].i = inv;
                return;
            }
        }
        self.inv_mass[b].i = [out[0][0], out[0][1], out[0][2], out[1][1], out[1][2], out[2][2]];
    }
}

/// q / |q| (the identity for a zero quaternion).
pub fn normalize(q: [f64; 4]) -> [f64; 4] {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if n > 0.0 {
        [q[0] / n, q[1] / n, q[2] / n, q[3] / n]
    } else {
        [1.0, 0.0, 0.0, 0.0]
    }
}

/// The rotation matrix of a unit quaternion (rows).
pub fn rotation_matrix(q: [f64; 4]) -> [[f64; 3]; 3] {
    let [w, x, y, z] = q;
    [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
        [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
        [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)],
    ]
}

/// R v.
pub fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let r = rotation_matrix(q);
    [dot(r[0], v), dot(r[1], v), dot(r[2], v)]
}

/// Rᵀ v.
pub fn rotate_inv(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    rotate([q[0], -q[1], -q[2], -q[3]], v)
}

/// The quaternion of a rotation vector (axis × angle, rad).
pub fn from_rotation_vector(r: [f64; 3]) -> [f64; 4] {
    let a = dot(r, r).sqrt();
    if a == 0.0 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let (s, c) = (0.5 * a).sin_cos();
    [c, s * r[0] / a, s * r[1] / a, s * r[2] / a]
}

/// The rotation vector of a unit quaternion.
pub fn to_rotation_vector(q: [f64; 4]) -> [f64; 3] {
    let q = if q[0] < 0.0 { [-q[0], -q[1], -q[2], -q[3]] } else { q };
    let s = (q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if s == 0.0 {
        return [0.0; 3];
    }
    let a = 2.0 * s.atan2(q[0]);
    [a * q[1] / s, a * q[2] / s, a * q[3] / s]
}

/// a ⊗ b.
pub fn quat_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn rotations() {
        let q = from_rotation_vector([0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        let v = rotate(q, [1.0, 0.0, 0.0]);
        assert!((v[0]).abs() < 1e-15 && (v[1] - 1.0).abs() < 1e-15);
        let back = rotate_inv(q, v);
        assert!((back[0] - 1.0).abs() < 1e-15);
        let r = to_rotation_vector(q);
        assert!((r[2] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        let q2 = quat_mul(q, q);
        let v2 = rotate(q2, [1.0, 0.0, 0.0]);
        assert!((v2[0] + 1.0).abs() < 1e-15);
    }
    #[test]
    fn restricted_inverse_inertia() {
        let mut b = Bodies3::default();
        let s = ShapeRef { kind: 0, index: 0 };
        b.push(
            [0.0; 3],
            from_rotation_vector([0.3, -0.2, 0.5]),
            [0.0; 6],
            2.0,
            [1.0, 2.0, 3.0],
            1.0,
            s,
            0,
        );
        let iw = b.world_inertia(0);
        let inv = crate::dim::coulomb3::inverse(&iw).unwrap();
        for k in 0..6 {
            assert!((inv[k] - b.inv_mass[0].i[k]).abs() < 1e-14);
        }
        // z rotation driven: the xy block inverted alone
        b.free[0] = ALL_FREE & !(1 << 5);
        b.refresh_inverse(0);
        let ii = b.inv_mass[0].i;
        assert_eq!((ii[2], ii[4], ii[5]), (0.0, 0.0, 0.0));
        let det = iw[0] * iw[3] - iw[1] * iw[1];
        assert!((ii[0] - iw[3] / det).abs() < 1e-14);
    }
}
