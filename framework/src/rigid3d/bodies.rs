//! 3D rigid bodies: [`Bodies3`], the generic [`crate::model::Bodies`] with
//! [`crate::dim::D3`]'s twist (v, ω), unit quaternions and M̂⁻¹; the rotation
//! algebra is [`crate::dim::rotation`]'s.

pub use crate::dim::d3::{cross, dot};
pub use crate::dim::rotation::*;
pub use crate::model::ShapeRef;

/// 3D rigid bodies.
pub type Bodies3 = crate::model::Bodies<crate::dim::D3>;

/// All six degrees of freedom free.
pub const ALL_FREE: u8 = crate::model::bodies::all_free::<crate::dim::D3>();

impl Bodies3 {
    /// World inertia tensor I_w = R diag(I) Rᵀ (upper triangle).
    pub fn world_inertia(&self, b: usize) -> crate::dim::coulomb3::Sym3 {
        crate::dim::d3::world_inertia(&self.rot[b], &self.inertia[b])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
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
