//! Rigid bodies in 3D: the one-contact Coulomb solver ([`coulomb`]).

pub mod coulomb;
