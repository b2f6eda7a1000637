//! What a simulation holds, for any dimension: the contact set ([`contacts`]).
//! Imports only [`crate::dim`]: never the solver, NSCDD or io.

pub mod contacts;

pub use contacts::{ContactKey, Contacts, Target};
