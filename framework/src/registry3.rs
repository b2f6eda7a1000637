//! What 3D plugins register: shape kinds with their stores, pair detectors keyed by
//! the pair of shape kinds, and generators; the 3D counterparts of the 2D traits in
//! [`crate::registry`], held by the same [`Registry`]. A 3D shape store sees poses as
//! a position and a unit quaternion `(w, x, y, z)`.

use crate::registry::{ParamError, Registry};
use crate::rigid3d::Bodies3;
use crate::scene::builder3::SceneBuilder3;
use std::any::Any;
use std::sync::Arc;

/// Axis-aligned bounding box in 3D.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb3 {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl Aabb3 {
    pub fn overlaps(&self, o: &Aabb3, margin: f64) -> bool {
        (0..3).all(|k| self.min[k] <= o.max[k] + margin && o.min[k] <= self.max[k] + margin)
    }
    pub fn is_bounded(&self) -> bool {
        self.min.iter().chain(&self.max).all(|x| x.is_finite())
    }
    pub fn extent(&self) -> f64 {
        (0..3).map(|k| self.max[k] - self.min[k]).fold(0.0, f64::max)
    }
}

/// Mass properties of one 3D shape for a density, in the shape's principal frame
/// (the body frame): the shape must be described with its centre of mass at the
/// origin and its principal axes along the body axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProps3 {
    pub volume: f64,
    pub mass: f64,
    /// Principal moments of inertia about the centre of mass.
    pub inertia: [f64; 3],
}

/// How a 3D shape is drawn in the VTK output.
#[derive(Clone, Debug, PartialEq)]
pub enum Glyph3 {
    /// A particle of this radius at the body's position.
    Sphere(f64),
    /// A closed convex polygon face set (world coordinates): each face a vertex loop.
    Faces(Vec<Vec<[f64; 3]>>),
}

/// The store of all 3D shapes of one kind (struct-of-arrays, owned by a plugin).
pub trait ShapeStore3: Any + Send + Sync {
    fn kind(&self) -> &'static str;
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    fn as_any(&self) -> &dyn Any;
    fn as_any_mut(&mut self) -> &mut dyn Any;
    /// Parses one shape from a body's shape-specific keys and stores it.
    fn push_params(&mut self, params: &toml::Table) -> Result<u32, ParamError>;
    /// Bounding box at a pose (unbounded shapes return infinite bounds).
    fn aabb(&self, s: u32, pos: [f64; 3], quat: [f64; 4]) -> Aabb3;
    fn mass_properties(&self, s: u32, density: f64) -> MassProps3;
    /// A typical length (radius of a sphere): detection grid, default alert.
    fn size(&self, s: u32) -> f64;
    fn glyph(&self, s: u32, pos: [f64; 3], quat: [f64; 4]) -> Glyph3;
    /// Shape parameters for `final.json`.
    fn describe(&self, s: u32) -> serde_json::Value;
    /// Whether bodies of this kind count as grains (solid fraction, coordination).
    fn is_grain(&self) -> bool {
        true
    }
    /// A point p (world frame) against this shape's surface at a pose (a boundary
    /// node of a deformable body): the signed distance (the gap), the unit outward
    /// normal at the closest surface point, and that point. `hint` is the outward
    /// normal of the deformable body's surface at the node (zero if unknown): where
    /// several faces of the shape are at the same distance (a node on an edge of
    /// a block resting on it), the one facing the node's surface is meant. `None`:
    /// this kind does not meet points.
    fn point_contact(&self, _s: u32, _pos: [f64; 3], _quat: [f64; 4], _p: [f64; 3], _hint: [f64; 3]) -> Option<PointContact3> {
        None
    }
    /// Where the shape's principal frame (centroid, principal axes) lies in the frame
    /// its parameters were given in, as (centroid, unit quaternion): a body placed at
    /// (x, q) in that frame is stored at x + q·c with orientation q ⊗ q_c, so that
    /// its position is its centre of mass. Identity for shapes described in their
    /// principal frame.
    fn principal_frame(&self, _s: u32) -> ([f64; 3], [f64; 4]) {
        ([0.0; 3], [1.0, 0.0, 0.0, 0.0])
    }
    /// Whether this kind implements [`Self::face_contact`].
    fn meets_faces(&self) -> bool {
        false
    }
    /// A triangle (world frame, a boundary face of a deformable body) against this
    /// shape at a pose: the closest point of the triangle (barycentric weights),
    /// the gap, the unit normal from the shape towards the triangle and the point
    /// of the shape's surface. Kinds that implement it meet deformable bodies by
    /// their faces instead of by the bodies' nodes (round grains smaller than the
    /// mesh would otherwise pass between nodes).
    fn face_contact(&self, _s: u32, _pos: [f64; 3], _quat: [f64; 4], _tri: &[[f64; 3]; 3]) -> Option<FaceContact3> {
        None
    }
}

/// A shape against a triangle ([`ShapeStore3::face_contact`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceContact3 {
    pub gap: f64,
    /// From the shape towards the triangle.
    pub normal: [f64; 3],
    /// Point of the shape's surface.
    pub point: [f64; 3],
    /// Weights of the triangle's corners at its closest point.
    pub bary: [f64; 3],
}

/// A point against a shape's surface ([`ShapeStore3::point_contact`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointContact3 {
    pub gap: f64,
    /// From the shape towards the point.
    pub normal: [f64; 3],
    /// Closest point of the surface.
    pub point: [f64; 3],
}

/// A raw 3D contact found by a narrow phase.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawContact3 {
    /// Candidate and antagonist bodies; the normal points from j to i.
    pub i: u32,
    pub j: u32,
    /// Feature index for shapes that touch at several points (0 otherwise).
    pub feature: u32,
    pub point: [f64; 3],
    pub normal: [f64; 3],
    /// Signed distance (negative: interpenetration).
    pub gap: f64,
    /// Area of contact this point stands for (m²; 0 for point contacts): what
    /// bonded joints scale their strengths with.
    pub area: f64,
}

/// What a 3D narrow phase sees.
pub struct DetectCtx3<'a> {
    pub a: &'a dyn ShapeStore3,
    pub b: &'a dyn ShapeStore3,
    pub bodies: &'a Bodies3,
    pub alert: f64,
}

/// A narrow phase for one pair of 3D shape kinds; `pairs[k] = [body of kind A, body
/// of kind B]` in the order the detector was registered with.
pub trait PairDetector3: Send + Sync {
    fn detect(&self, ctx: &DetectCtx3<'_>, pairs: &[[u32; 2]], out: &mut Vec<RawContact3>);
}

/// Makes 3D bodies from parameters (`[[generate]]` of a 3D scene).
pub trait Generator3: Send + Sync {
    fn generate(&self, params: &toml::Table, out: &mut SceneBuilder3<'_>) -> Result<(), ParamError>;
}

/// A 3D shape kind: its name and how to make its empty store.
pub struct ShapeKindDef3 {
    pub name: &'static str,
    pub new_store: fn() -> Box<dyn ShapeStore3>,
}

impl Registry {
    pub fn add_shape3(&mut self, def: ShapeKindDef3) {
        self.shapes3.insert(def.name, def);
    }
    pub fn add_detector3(&mut self, a: &'static str, b: &'static str, d: Arc<dyn PairDetector3>) {
        self.detectors3.insert((a, b), d);
    }
    pub fn add_generator3(&mut self, name: &'static str, g: Box<dyn Generator3>) {
        self.generators3.insert(name, g);
    }
    pub fn shape_kinds3(&self) -> Vec<&'static str> {
        self.shapes3.keys().copied().collect()
    }
    pub fn generator_names3(&self) -> Vec<&'static str> {
        self.generators3.keys().copied().collect()
    }
    /// The 3D detector for a pair of kinds, and whether the registered order is (b, a).
    pub fn detector3(&self, a: &str, b: &str) -> Option<(Arc<dyn PairDetector3>, bool)> {
        if let Some((_, d)) = self.detectors3.iter().find(|((x, y), _)| *x == a && *y == b) {
            return Some((d.clone(), false));
        }
        self.detectors3
            .iter()
            .find(|((x, y), _)| *x == b && *y == a)
            .map(|(_, d)| (d.clone(), true))
    }
}
