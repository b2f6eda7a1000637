//! Rigid bodies in 3D: six degrees of freedom with quaternion orientations
//! ([`bodies`]), the contact set ([`contacts`]), the one-contact Coulomb solver
//! ([`coulomb`]), bonded mortar joints ([`joint`]) and NLGS ([`nlgs`]).

pub mod bodies;
pub mod contacts;
pub mod coulomb;
pub mod joint;
pub mod nlgs;

pub use bodies::Bodies3;
pub use contacts::Contacts3;
