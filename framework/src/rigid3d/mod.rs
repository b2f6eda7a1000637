//! Rigid bodies in 3D: six degrees of freedom with quaternion orientations
//! ([`bodies`]) and the 3D contact set ([`Contacts3`], the generic
//! [`crate::model::Contacts`]); the kinematics are [`crate::dim::D3`]'s.

pub mod bodies;

/// The 3D contact set and its frame and block types.
pub mod contacts {
    pub use crate::dim::d3::{apply, local_velocity, point_velocity, tangents, Block3, Frame3, InvMass3};
}

pub use bodies::Bodies3;

/// The 3D contact set.
pub type Contacts3 = crate::model::Contacts<crate::dim::D3>;
