//! # nscdd-polygons: 2D rigid convex polygons, a plugin loaded at run time
//!
//! LMGC90's POLYG in nscdd: angular grains and 2D masonry. This crate is the worked
//! example of `docs/PLUGINS.md`: it is built as a shared library
//! (`libnscdd_polygons.so`) and loaded by `nscdd` when it starts — the `nscdd`
//! program does not link it.
//!
//! - Shape `polygon` ([`shapes::Polygons`]): `vertices = [[x, y], …]` (the convex
//!   hull is taken), `sides` with `radius` (regular), or `size = [w, h]`; mass and
//!   polar moment from the geometry; the body's position becomes the centroid.
//! - Detectors ([`detect`]): polygon–polygon (up to two points per pair:
//!   vertex–edge and edge–edge overlaps, stable feature ids), polygon–disk,
//!   polygon–wall and polygon–half-plane (the shapes of the built-in disks plugin,
//!   read through the `ShapeStore` trait).
//! - Generators ([`generate`]): `polygon_deposit`, `brick_wall_2d`, `arch_2d`.
//! - VTK output: each polygon drawn as its polygon (`Glyph::Polygon`).
//!
//! A scene loads it with
//!
//! ```toml
//! [[plugins]]
//! library = "../../../target/release/libnscdd_polygons.so"
//! [[bodies]]
//! shape = "polygon"
//! sides = 5
//! radius = 0.01
//! material = "stone"
//! position = [0.0, 0.02]
//! ```
//!
//! and a program that links it statically (its unit tests, the static-vs-dynamic
//! benchmark) adds [`PolygonsPlugin`] to its registry, beside the disks plugin
//! whose half-planes, walls and disks it meets:
//!
//! ```
//! let mut reg = nscdd::registry::Registry::new();
//! reg.add_plugin(&nscdd_polygons::PolygonsPlugin);
//! assert!(reg.shape_kinds::<nscdd::dim::D2>().contains(&"polygon"));
//! ```

pub mod detect;
pub mod generate;
pub mod shapes;

use nscdd::dim::D2;
use nscdd::registry::{Plugin, Registry, ShapeKindDef};
use shapes::Polygons;
use std::sync::Arc;

/// The plugin: what it adds to nscdd's registry.
pub struct PolygonsPlugin;

impl Plugin for PolygonsPlugin {
    fn name(&self) -> &'static str {
        "polygons"
    }
    fn build(&self, reg: &mut Registry) {
        reg.add_shape(ShapeKindDef::<D2> {
            name: Polygons::KIND,
            new_store: || Box::new(Polygons::default()),
        });
        reg.add_detector::<D2>(Polygons::KIND, Polygons::KIND, Arc::new(detect::PolyPoly));
        reg.add_detector::<D2>(Polygons::KIND, "disk", Arc::new(detect::PolyRound));
        reg.add_detector::<D2>(Polygons::KIND, "wall", Arc::new(detect::PolyRound));
        reg.add_detector::<D2>(Polygons::KIND, "halfplane", Arc::new(detect::PolyHalfPlane));
        reg.add_generator::<D2>("polygon_deposit", Box::new(generate::PolygonDeposit));
        reg.add_generator::<D2>("brick_wall_2d", Box::new(generate::BrickWall2d));
        reg.add_generator::<D2>("arch_2d", Box::new(generate::Arch2d));
    }
}

// The entry point nscdd looks for in the library (`nscdd_plugin_entry`).
nscdd::export_plugin!(PolygonsPlugin);
