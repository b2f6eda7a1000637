//! # nscdd-polyhedra: 3D rigid convex polyhedra for masonry
//!
//! Shape `polyhedron` (scenes with `dimension = 3`): key `vertices` = [[x, y, z], …]
//! (the convex hull is taken; at most 64 points). Mass and inertia come from the
//! geometry; the body's position becomes its centroid and its orientation its
//! principal axes. Detectors polyhedron–polyhedron (several points per face–face
//! and edge–face contact, [`detect`]), polyhedron–plane and polyhedron–sphere (the
//! `plane` and `sphere` kinds of the spheres plugin, which must be registered
//! too). Generators `brick_wall` (running bond on a base) and `arch` (radial
//! voussoirs on two supports).
//!
//! ```
//! let mut reg = nscdd::registry::Registry::new();
//! reg.add_plugin(&nscdd_spheres::SpheresPlugin);
//! reg.add_plugin(&nscdd_polyhedra::PolyhedraPlugin);
//! assert!(reg.shape_kinds::<nscdd::dim::D3>().contains(&"polyhedron"));
//! ```

pub mod detect;
pub mod detect_plane_sphere;
pub mod generate;
pub mod hull;
pub mod shapes;

use nscdd::registry::ShapeKindDef;
use nscdd::registry::{Plugin, Registry};
use shapes::Polyhedra;
use std::sync::Arc;

/// The plugin.
pub struct PolyhedraPlugin;

impl Plugin for PolyhedraPlugin {
    fn name(&self) -> &'static str {
        "polyhedra"
    }
    fn build(&self, reg: &mut Registry) {
        reg.add_shape(ShapeKindDef {
            name: Polyhedra::KIND,
            new_store: || Box::new(Polyhedra::default()),
        });
        reg.add_detector(Polyhedra::KIND, Polyhedra::KIND, Arc::new(detect::PolyPoly));
        reg.add_detector(Polyhedra::KIND, nscdd_spheres::shapes::Planes::KIND, Arc::new(detect::PolyPlane));
        reg.add_detector(Polyhedra::KIND, nscdd_spheres::shapes::Spheres::KIND, Arc::new(detect::PolySphere));
        reg.add_generator("brick_wall", Box::new(generate::BrickWall));
        reg.add_generator("arch", Box::new(generate::Arch));
        reg.add_generator("tilting_table", Box::new(generate::TiltingTable));
    }
}

/// A registry with the spheres plugin (planes, spheres) and this one.
pub fn registry() -> Registry {
    let mut r = Registry::new();
    r.add_plugin(&nscdd_spheres::SpheresPlugin);
    r.add_plugin(&PolyhedraPlugin);
    r
}
