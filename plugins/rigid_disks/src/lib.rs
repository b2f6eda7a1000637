//! # nscdd-rigid-disks: 2D rigid disks, walls and half-planes
//!
//! Shapes (scene key `shape`):
//! - `disk`: key `radius` (m);
//! - `wall`: keys `length`, `thickness` (m), a thick segment with rounded ends along
//!   the body's rotated x axis (like LMGC90's JONCx);
//! - `halfplane`: the body's position is on the boundary, the rotation θ turns the
//!   outward normal (−sin θ, cos θ); optional `display_length` for VTK.
//!
//! Detectors for every pair of these kinds except half-plane–half-plane, and
//! generators `disk_deposit`, `square_lattice`, `triangular_lattice`.
//!
//! ```
//! let mut reg = nscdd::registry::Registry::new();
//! reg.add_plugin(&nscdd_rigid_disks::RigidDisks);
//! assert!(reg.shape_kinds::<nscdd::dim::D2>().contains(&"disk"));
//! ```

pub mod detect;
pub mod generate;
pub mod shapes;

use nscdd::registry::{Plugin, Registry, ShapeKindDef};
use shapes::{Disks, HalfPlanes, Walls};
use std::sync::Arc;

/// The plugin.
pub struct RigidDisks;

impl Plugin for RigidDisks {
    fn name(&self) -> &'static str {
        "rigid_disks"
    }
    fn build(&self, reg: &mut Registry) {
        reg.add_shape(ShapeKindDef {
            name: Disks::KIND,
            new_store: || Box::new(Disks::default()),
        });
        reg.add_shape(ShapeKindDef {
            name: Walls::KIND,
            new_store: || Box::new(Walls::default()),
        });
        reg.add_shape(ShapeKindDef {
            name: HalfPlanes::KIND,
            new_store: || Box::new(HalfPlanes::default()),
        });
        reg.add_detector(Disks::KIND, Disks::KIND, Arc::new(detect::DiskDisk));
        reg.add_detector(Disks::KIND, Walls::KIND, Arc::new(detect::DiskWall));
        reg.add_detector(Disks::KIND, HalfPlanes::KIND, Arc::new(detect::DiskHalfPlane));
        reg.add_detector(Walls::KIND, Walls::KIND, Arc::new(detect::WallWall));
        reg.add_detector(Walls::KIND, HalfPlanes::KIND, Arc::new(detect::WallHalfPlane));
        reg.add_generator("disk_deposit", Box::new(generate::DiskDeposit));
        reg.add_generator("square_lattice", Box::new(generate::SquareLattice));
        reg.add_generator("triangular_lattice", Box::new(generate::TriangularLattice));
    }
}

/// A registry with the framework's built-ins and this plugin.
pub fn registry() -> Registry {
    let mut r = Registry::new();
    r.add_plugin(&RigidDisks);
    r
}
