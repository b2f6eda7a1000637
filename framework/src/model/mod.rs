//! What a simulation holds, for any dimension: the bodies
//! ([`bodies`]), their slots and global ids ([`ids`]) and the contact set
//! ([`contacts`]).
//! Imports only [`crate::dim`]: never the solver, NSCDD or io.

pub mod bodies;
pub mod contacts;
pub mod ids;

pub use bodies::{all_free, Bodies, ShapeRef};
pub use contacts::{ContactKey, Contacts, Target};
pub use ids::BodyIds;

use crate::dim::{D2, D3};

/// 2D rigid bodies: twist (v_x, v_y, ω), angles, diagonal M̂⁻¹.
pub type Bodies2 = Bodies<D2>;
/// 3D rigid bodies: twist (v, ω), unit quaternions, world-frame M̂⁻¹.
pub type Bodies3 = Bodies<D3>;
/// The 2D contact set.
pub type Contacts2 = Contacts<D2>;
/// The 3D contact set.
pub type Contacts3 = Contacts<D3>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dim::rotation::from_rotation_vector;
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
        let iw = crate::dim::d3::world_inertia(&b.rot[0], &b.inertia[0]);
        let inv = crate::dim::coulomb3::inverse(&iw).unwrap();
        for k in 0..6 {
            assert!((inv[k] - b.inv_mass[0].i[k]).abs() < 1e-14);
        }
        // z rotation driven: the xy block inverted alone
        b.free[0] = all_free::<D3>() & !(1 << 5);
        b.refresh_inverse(0);
        let ii = b.inv_mass[0].i;
        assert_eq!((ii[2], ii[4], ii[5]), (0.0, 0.0, 0.0));
        let det = iw[0] * iw[3] - iw[1] * iw[1];
        assert!((ii[0] - iw[3] / det).abs() < 1e-14);
    }
}
