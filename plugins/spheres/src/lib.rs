//! # nscdd-spheres: 3D rigid spheres, planes and boxes
//!
//! Shapes (scene key `shape`, in scenes with `dimension = 3`):
//! - `sphere`: key `radius` (m);
//! - `plane`: a half-space whose boundary holds the body's position, outward normal
//!   along the body's z axis (set `rotation`, a rotation vector); optional
//!   `display_size`. Fix it or drive it by velocity (it has only a nominal mass);
//! - `box`: a rectangular cuboid, key `half_extents` = [a, b, c] (m) along the body
//!   axes; thin boxes make the walls of a sample cell.
//!
//! Detectors sphere–sphere, sphere–plane and sphere–box; generators
//! `sphere_packing` (random, in a box or a cylinder) and `sphere_lattice`.
//!
//! ```
//! let mut reg = nscdd::registry::Registry::new();
//! reg.add_plugin(&nscdd_spheres::SpheresPlugin);
//! assert!(reg.shape_kinds::<nscdd::dim::D3>().contains(&"sphere"));
//! ```

pub mod detect;
pub mod generate;
pub mod shapes;

use nscdd::registry::ShapeKindDef;
use nscdd::registry::{Plugin, Registry};
use shapes::{Boxes, Planes, Spheres};
use std::sync::Arc;

/// The plugin.
pub struct SpheresPlugin;

impl Plugin for SpheresPlugin {
    fn name(&self) -> &'static str {
        "spheres"
    }
    fn build(&self, reg: &mut Registry) {
        reg.add_shape(ShapeKindDef {
            name: Spheres::KIND,
            new_store: || Box::new(Spheres::default()),
        });
        reg.add_shape(ShapeKindDef {
            name: Planes::KIND,
            new_store: || Box::new(Planes::default()),
        });
        reg.add_shape(ShapeKindDef {
            name: Boxes::KIND,
            new_store: || Box::new(Boxes::default()),
        });
        reg.add_detector(Spheres::KIND, Spheres::KIND, Arc::new(detect::SphereSphere));
        reg.add_detector(Spheres::KIND, Planes::KIND, Arc::new(detect::SpherePlane));
        reg.add_detector(Spheres::KIND, Boxes::KIND, Arc::new(detect::SphereBox));
        reg.add_generator("sphere_packing", Box::new(generate::SpherePacking));
        reg.add_generator("sphere_lattice", Box::new(generate::SphereLattice));
    }
}

/// A registry with the framework's built-ins and this plugin.
pub fn registry() -> Registry {
    let mut r = Registry::new();
    r.add_plugin(&SpheresPlugin);
    r
}
