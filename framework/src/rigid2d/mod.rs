//! Rigid bodies in 2D: the struct-of-arrays body storage ([`Bodies2`]) and the 2D
//! contact set ([`Contacts2`], the generic [`crate::model::Contacts`]); the
//! kinematics are [`crate::dim::D2`]'s.

pub mod bodies;

/// The 2D contact set and its frame and block types.
pub mod contacts {
    pub use crate::dim::d2::{apply, local_velocity, Block2, Frame2};
    pub use crate::model::contacts::{ContactKey, Target};
}

pub use bodies::Bodies2;

/// The 2D contact set.
pub type Contacts2 = crate::model::Contacts<crate::dim::D2>;
