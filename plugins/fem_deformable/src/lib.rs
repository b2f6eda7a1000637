//! # Deformable bodies: linear elastic finite elements, coupled to rigid bodies
//!
//! A body family of the framework ([`nscdd::family`]): [`FemPlugin`] registers the
//! `[[deformable]]` section of 2D and 3D scenes ([`family::DeformableKind`]); the
//! framework loads, steps (glued by the one NSCDD stage through
//! [`nscdd::dd::Attached`], [`family2`], [`family3`]), writes and restarts it.
pub mod bench;
pub mod body;
pub mod contact2;
pub mod contact3;
pub mod continuum;
pub mod family;
pub mod family2;
pub mod family3;
pub mod impulses;
pub mod matrices;
pub mod mesh;
pub mod near;
pub mod nodes;
pub mod output;
pub mod problem;
pub mod python;
pub mod scene;
pub mod shells;
pub mod solved;
pub mod stage2;
pub mod stage3;
pub mod stepped;
pub mod warm;
pub mod whole;

use nscdd::dim::{D2, D3};
use nscdd::registry::{Plugin, Registry};

/// The plugin: the `[[deformable]]` and `[[continuum]]` sections in 2D and 3D scenes.
pub struct FemPlugin;

impl Plugin for FemPlugin {
    fn name(&self) -> &'static str {
        "fem_deformable"
    }
    fn build(&self, reg: &mut Registry) {
        reg.add_family::<D2>(family::SECTION, Box::new(family::DeformableKind));
        reg.add_family::<D3>(family::SECTION, Box::new(family::DeformableKind));
        reg.add_family::<D2>(continuum::SECTION, Box::new(continuum::scene::ContinuumKind));
        reg.add_family::<D3>(continuum::SECTION, Box::new(continuum::scene::ContinuumKind));
    }
}
