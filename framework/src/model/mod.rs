//! What a simulation holds, for any dimension: the bodies
//! ([`bodies`]) and the contact set ([`contacts`]).
//! Imports only [`crate::dim`]: never the solver, NSCDD or io.

pub mod bodies;
pub mod contacts;

pub use bodies::{all_free, Bodies, ShapeRef};
pub use contacts::{ContactKey, Contacts, Target};
