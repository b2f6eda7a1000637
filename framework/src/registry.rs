//! The plugin registry: what plugins add to the framework.
//!
//! A [`Plugin`] registers, by name, shape kinds (each with its own struct-of-arrays
//! store), pair detectors keyed by the pair of shape kinds, body generators, contact
//! laws and writers. The framework names no plugin: scenes refer to these names, and
//! [`crate::scene`] resolves them once at load time; a pair of shape kinds that can
//! meet in a scene but has no detector is an error then. After setup the time loop
//! holds concrete data; detectors are called once per batch of candidate pairs, never
//! per contact inside the solver.
//!
//! ```
//! use nscdd::registry::{Plugin, Registry};
//! struct Nothing;
//! impl Plugin for Nothing {
//!     fn name(&self) -> &'static str { "nothing" }
//!     fn build(&self, _reg: &mut Registry) {}
//! }
//! let mut reg = Registry::new();
//! reg.add_plugin(&Nothing);
//! assert!(reg.plugins().contains(&"nothing"));
//! ```

use crate::law::LawDef;
use crate::rigid2d::Bodies2;
use crate::scene::builder::SceneBuilder2;
use std::any::Any;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Axis-aligned bounding box in 2D.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb2 {
    pub min: [f64; 2],
    pub max: [f64; 2],
}

impl Aabb2 {
    pub fn overlaps(&self, o: &Aabb2, margin: f64) -> bool {
        self.min[0] <= o.max[0] + margin
            && o.min[0] <= self.max[0] + margin
            && self.min[1] <= o.max[1] + margin
            && o.min[1] <= self.max[1] + margin
    }
    pub fn is_bounded(&self) -> bool {
        self.min.iter().chain(&self.max).all(|x| x.is_finite())
    }
}

/// Mass properties of one shape for a density (2D: per unit depth).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProps2 {
    pub area: f64,
    pub mass: f64,
    /// Moment of inertia about the centre of mass.
    pub inertia: f64,
}

/// How a shape is drawn in the VTK output.
#[derive(Clone, Debug, PartialEq)]
pub enum Glyph2 {
    /// A particle of this radius at the body's position.
    Disk(f64),
    /// A closed polygon (world coordinates).
    Polygon(Vec<[f64; 2]>),
    /// A line through two points with a thickness.
    Segment([f64; 2], [f64; 2], f64),
}

/// A shape-specific key that failed, with the reason (located in the scene file by
/// the loader).
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    pub key: String,
    pub msg: String,
}

impl ParamError {
    pub fn new(key: impl Into<String>, msg: impl Into<String>) -> Self {
        ParamError {
            key: key.into(),
            msg: msg.into(),
        }
    }
}

/// The store of all shapes of one kind (struct-of-arrays, owned by a plugin).
pub trait ShapeStore2: Any + Send + Sync {
    fn kind(&self) -> &'static str;
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    fn as_any(&self) -> &dyn Any;
    fn as_any_mut(&mut self) -> &mut dyn Any;
    /// Parses one shape from a body's shape-specific keys and stores it.
    fn push_params(&mut self, params: &toml::Table) -> Result<u32, ParamError>;
    /// Bounding box of shape `s` at a pose. Unbounded shapes (half-planes) return
    /// infinite bounds and are tested against every body.
    fn aabb(&self, s: u32, pos: [f64; 2], rot: f64) -> Aabb2;
    fn mass_properties(&self, s: u32, density: f64) -> MassProps2;
    /// A length typical of the shape (radius for a disk), used to size the detection
    /// grid and the default alert distance.
    fn size(&self, s: u32) -> f64;
    fn glyph(&self, s: u32, pos: [f64; 2], rot: f64) -> Glyph2;
    /// Shape parameters for `final.json`.
    fn describe(&self, s: u32) -> serde_json::Value;
    /// Whether bodies of this kind count in the solid fraction of a box sample.
    fn is_grain(&self) -> bool {
        true
    }
    /// Contact of shape `s` at a pose with a point `p` (a boundary node of a
    /// deformable body): the signed distance from the surface (the gap), the unit
    /// outward normal of the surface at the closest point, and that point. `None`:
    /// this kind does not meet points (a scene that needs it is refused at load).
    fn point_contact(&self, _s: u32, _pos: [f64; 2], _rot: f64, _p: [f64; 2]) -> Option<PointContact2> {
        None
    }
}

/// A point against a shape's surface ([`ShapeStore2::point_contact`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointContact2 {
    pub gap: f64,
    /// From the shape towards the point.
    pub normal: [f64; 2],
    /// Closest point of the surface.
    pub point: [f64; 2],
}

/// A raw contact found by a narrow phase, before the law is applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawContact2 {
    /// Candidate and antagonist bodies; the normal points from j to i.
    pub i: u32,
    pub j: u32,
    /// Feature index for shapes that touch at several points (0 otherwise).
    pub feature: u32,
    pub point: [f64; 2],
    pub normal: [f64; 2],
    /// Signed distance (negative: interpenetration).
    pub gap: f64,
}

/// What a narrow phase sees.
pub struct DetectCtx<'a> {
    /// Store of the first kind of the registered pair, and of the second.
    pub a: &'a dyn ShapeStore2,
    pub b: &'a dyn ShapeStore2,
    pub bodies: &'a Bodies2,
    /// Contacts are reported while the gap is below the alert distance.
    pub alert: f64,
}

/// A narrow phase for one pair of shape kinds. `pairs[k] = [body of kind A, body of
/// kind B]` in the order the detector was registered with.
pub trait PairDetector2: Send + Sync {
    fn detect(&self, ctx: &DetectCtx<'_>, pairs: &[[u32; 2]], out: &mut Vec<RawContact2>);
}

/// Makes bodies from parameters (`[[generate]]` sections of a scene).
pub trait Generator2: Send + Sync {
    fn generate(&self, params: &toml::Table, out: &mut SceneBuilder2<'_>) -> Result<(), ParamError>;
}

/// Writes extra outputs every `output.every` steps (`[output] writers = [...]`).
pub trait Writer2: Send {
    fn write(&mut self, world: &crate::world::World2, dir: &std::path::Path, frame: u32) -> std::io::Result<()>;
    /// A frame of a decomposed (NSCDD) run, with the subdomains of the bodies and
    /// contacts; by default the plain frame.
    fn write_dd(
        &mut self,
        world: &crate::world::World2,
        _dd: &crate::dd::DdView,
        dir: &std::path::Path,
        frame: u32,
    ) -> std::io::Result<()> {
        self.write(world, dir, frame)
    }
    /// Called once at the end of the run.
    fn finish(&mut self, _dir: &std::path::Path) -> std::io::Result<()> {
        Ok(())
    }
}

/// A shape kind: its name and how to make its empty store.
pub struct ShapeKindDef {
    pub name: &'static str,
    pub new_store: fn() -> Box<dyn ShapeStore2>,
}

/// The plugin interface, after bevy's `Plugin`: add what you provide to the registry.
pub trait Plugin {
    fn name(&self) -> &'static str;
    fn build(&self, reg: &mut Registry);
}

/// Everything plugins provide, by name.
#[derive(Default)]
pub struct Registry {
    plugins: Vec<&'static str>,
    pub(crate) shapes: BTreeMap<&'static str, ShapeKindDef>,
    pub(crate) detectors: BTreeMap<(&'static str, &'static str), Arc<dyn PairDetector2>>,
    pub(crate) generators: BTreeMap<&'static str, Box<dyn Generator2>>,
    pub(crate) laws: BTreeMap<&'static str, LawDef>,
    pub(crate) writers: BTreeMap<&'static str, fn() -> Box<dyn Writer2>>,
    pub(crate) shapes3: BTreeMap<&'static str, crate::registry3::ShapeKindDef3>,
    pub(crate) detectors3: BTreeMap<(&'static str, &'static str), Arc<dyn crate::registry3::PairDetector3>>,
    pub(crate) generators3: BTreeMap<&'static str, Box<dyn crate::registry3::Generator3>>,
}

impl Registry {
    /// A registry holding the framework's own laws and writers.
    pub fn new() -> Self {
        let mut r = Registry::default();
        crate::law::register_builtin(&mut r);
        crate::output::vtk::register_builtin(&mut r);
        r
    }
    pub fn add_plugin(&mut self, p: &dyn Plugin) -> &mut Self {
        self.plugins.push(p.name());
        p.build(self);
        self
    }
    pub fn plugins(&self) -> Vec<&'static str> {
        self.plugins.clone()
    }
    pub fn add_shape(&mut self, def: ShapeKindDef) {
        self.shapes.insert(def.name, def);
    }
    pub fn add_detector(&mut self, a: &'static str, b: &'static str, d: Arc<dyn PairDetector2>) {
        self.detectors.insert((a, b), d);
    }
    pub fn add_generator(&mut self, name: &'static str, g: Box<dyn Generator2>) {
        self.generators.insert(name, g);
    }
    pub fn add_law(&mut self, def: LawDef) {
        self.laws.insert(def.name, def);
    }
    pub fn add_writer(&mut self, name: &'static str, make: fn() -> Box<dyn Writer2>) {
        self.writers.insert(name, make);
    }
    /// A writer's constructor by name.
    pub fn writer(&self, name: &str) -> Option<fn() -> Box<dyn Writer2>> {
        self.writers.get(name).copied()
    }
    pub fn shape_kinds(&self) -> Vec<&'static str> {
        self.shapes.keys().copied().collect()
    }
    pub fn generator_names(&self) -> Vec<&'static str> {
        self.generators.keys().copied().collect()
    }
    pub fn law_names(&self) -> Vec<&'static str> {
        self.laws.keys().copied().collect()
    }
    /// The detector for a pair of kinds, and whether the registered order is (b, a).
    pub fn detector(&self, a: &str, b: &str) -> Option<(Arc<dyn PairDetector2>, bool)> {
        if let Some((_, d)) = self.detectors.iter().find(|((x, y), _)| *x == a && *y == b) {
            return Some((d.clone(), false));
        }
        self.detectors
            .iter()
            .find(|((x, y), _)| *x == b && *y == a)
            .map(|(_, d)| (d.clone(), true))
    }
}
