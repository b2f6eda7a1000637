//! What a shape kind provides, once for 2D and 3D: its struct-of-arrays store
//! ([`ShapeStore`]), the narrow phase of a pair of kinds ([`PairDetector`]) and the
//! raw contacts it reports ([`RawContact`]). A plugin implements these for
//! `D = D2` or `D = D3` (or both) and registers them with the
//! [`crate::registry::Registry`]; the broad phase, the contact build and the
//! outputs are written once over `D: Dim`.
//!
//! ```
//! use nscdd::dim::D2;
//! use nscdd::shape::{Aabb, Glyph, MassProps, ShapeStore};
//! use nscdd::params::{number, ParamError};
//! use std::any::Any;
//!
//! /// Squares of side `a`, in 2D.
//! #[derive(Default)]
//! struct Squares { side: Vec<f64> }
//!
//! impl ShapeStore<D2> for Squares {
//!     fn kind(&self) -> &'static str { "square" }
//!     fn len(&self) -> usize { self.side.len() }
//!     fn as_any(&self) -> &dyn Any { self }
//!     fn as_any_mut(&mut self) -> &mut dyn Any { self }
//!     fn push_params(&mut self, p: &toml::Table) -> Result<u32, ParamError> {
//!         self.side.push(number(p, "side", None)?);
//!         Ok(self.side.len() as u32 - 1)
//!     }
//!     fn aabb(&self, s: u32, x: [f64; 2], _rot: f64) -> Aabb<D2> {
//!         let h = self.side[s as usize] * std::f64::consts::SQRT_2 / 2.0;
//!         Aabb { min: [x[0] - h, x[1] - h], max: [x[0] + h, x[1] + h] }
//!     }
//!     fn mass_properties(&self, s: u32, density: f64) -> MassProps<D2> {
//!         let a = self.side[s as usize];
//!         let m = density * a * a;
//!         MassProps { volume: a * a, mass: m, inertia: m * a * a / 6.0 }
//!     }
//!     fn size(&self, s: u32) -> f64 { self.side[s as usize] / 2.0 }
//!     fn glyph(&self, s: u32, x: [f64; 2], _rot: f64) -> Glyph<D2> { Glyph::Ball(self.size(s)) }
//!     fn describe(&self, s: u32) -> serde_json::Value { serde_json::json!({ "side": self.side[s as usize] }) }
//! }
//! let mut sq = Squares::default();
//! let s = sq.push_params(&toml::toml! { side = 2.0 }).unwrap();
//! assert_eq!(sq.mass_properties(s, 1.0).volume, 4.0);
//! ```

use crate::dim::{Dim, Vector, D2, D3};
use crate::model::Bodies;
pub use crate::params::ParamError;
use std::any::Any;

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb<D: Dim> {
    pub min: D::Point,
    pub max: D::Point,
}

impl<D: Dim> Aabb<D> {
    /// Whether the boxes overlap once grown by `margin`.
    #[inline]
    pub fn overlaps(&self, o: &Aabb<D>, margin: f64) -> bool {
        (0..D::N).all(|k| self.min[k] <= o.max[k] + margin && o.min[k] <= self.max[k] + margin)
    }
    pub fn is_bounded(&self) -> bool {
        self.min.as_ref().iter().chain(self.max.as_ref()).all(|x| x.is_finite())
    }
    /// The measure of the face normal to axis `k`: the product of the other sides
    /// (2D: a length, per unit depth).
    pub fn face(&self, k: usize) -> f64 {
        (0..D::N).filter(|&a| a != k).map(|a| self.max[a] - self.min[a]).product()
    }
    /// The largest side.
    pub fn extent(&self) -> f64 {
        (0..D::N).map(|k| self.max[k] - self.min[k]).fold(0.0, f64::max)
    }
    /// Min and max corners in three coordinates (z = 0 in 2D): the boxes the
    /// decomposition's regions test.
    pub fn corners3(&self) -> [[f64; 3]; 2] {
        let mut b = [[0.0; 3]; 2];
        b[0][..D::N].copy_from_slice(self.min.as_ref());
        b[1][..D::N].copy_from_slice(self.max.as_ref());
        b
    }
}

/// Mass properties of one shape for a density (2D: per unit depth), in the shape's
/// principal frame (the body frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProps<D: Dim> {
    /// Area in 2D, volume in 3D.
    pub volume: f64,
    pub mass: f64,
    /// Moment of inertia about the centre of mass (3D: the principal moments).
    pub inertia: D::Inertia,
}

/// How a shape is drawn in the VTK output (world coordinates).
#[derive(Clone, Debug, PartialEq)]
pub enum Glyph<D: Dim> {
    /// A disk or a sphere of this radius at the body's position.
    Ball(f64),
    /// A closed polygon (in 3D: one flat face).
    Polygon(Vec<D::Point>),
    /// A segment with a thickness (a 2D wall).
    Segment(D::Point, D::Point, f64),
    /// A closed polyhedral surface, each face a vertex loop (3D).
    Faces(Vec<Vec<D::Point>>),
}

/// A point against a shape's surface ([`ShapeStore::point_contact`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointContact<D: Dim> {
    pub gap: f64,
    /// From the shape towards the point.
    pub normal: D::Point,
    /// Closest point of the surface.
    pub point: D::Point,
}

/// A shape against a boundary facet of a deformable body (a segment in 2D, a
/// triangle in 3D; [`ShapeStore::face_contact`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceContact<D: Dim> {
    pub gap: f64,
    /// From the shape towards the facet.
    pub normal: D::Point,
    /// Point of the shape's surface.
    pub point: D::Point,
    /// Weights of the facet's N corners at its closest point.
    pub bary: D::Point,
}

/// The store of all shapes of one kind (struct-of-arrays, owned by a plugin).
pub trait ShapeStore<D: Dim>: Any + Send + Sync {
    fn kind(&self) -> &'static str;
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    fn as_any(&self) -> &dyn Any;
    fn as_any_mut(&mut self) -> &mut dyn Any;
    /// Parses one shape from a body's shape-specific keys and stores it.
    fn push_params(&mut self, params: &toml::Table) -> Result<u32, ParamError>;
    /// Bounding box of shape `s` at a pose. Unbounded shapes (half-planes, planes)
    /// return infinite bounds and are tested against every body.
    fn aabb(&self, s: u32, pos: D::Point, rot: D::Rot) -> Aabb<D>;
    fn mass_properties(&self, s: u32, density: f64) -> MassProps<D>;
    /// A length typical of the shape (radius of a disk or sphere): the detection
    /// grid and the default alert distance.
    fn size(&self, s: u32) -> f64;
    fn glyph(&self, s: u32, pos: D::Point, rot: D::Rot) -> Glyph<D>;
    /// Shape parameters for `final.json`.
    fn describe(&self, s: u32) -> serde_json::Value;
    /// Whether bodies of this kind count as grains (solid fraction, coordination).
    fn is_grain(&self) -> bool {
        true
    }
    /// A point p (a boundary node of a deformable body) against this shape's
    /// surface at a pose: the signed distance (the gap), the unit outward normal at
    /// the closest surface point, and that point. `hint` is the outward normal of
    /// the deformable body's surface at the node (zero if unknown): where several
    /// faces of the shape are at the same distance (a node on an edge of a block
    /// resting on it), the one facing the node's surface is meant. `None`: this
    /// kind does not meet points (a scene that needs it is refused at load).
    fn point_contact(&self, _s: u32, _pos: D::Point, _rot: D::Rot, _p: D::Point, _hint: D::Point) -> Option<PointContact<D>> {
        None
    }
    /// Where the shape's principal frame (centroid, principal axes) lies in the
    /// frame its parameters were given in: a body placed at (x, R) in that frame is
    /// stored at x + R c with orientation R ∘ R_c, so that its position is its
    /// centre of mass. Identity for shapes described in their principal frame.
    fn principal_frame(&self, _s: u32) -> (D::Point, D::Rot) {
        (D::Point::zero(), D::rot_identity())
    }
    /// Whether this kind implements [`Self::face_contact`].
    fn meets_faces(&self) -> bool {
        false
    }
    /// A boundary facet of a deformable body (its N corners, world frame) against
    /// this shape at a pose: the closest point of the facet (barycentric weights),
    /// the gap, the unit normal from the shape towards the facet and the point of
    /// the shape's surface. Kinds that implement it meet deformable bodies by their
    /// facets instead of by the bodies' nodes (round grains smaller than the mesh
    /// would otherwise pass between nodes).
    fn face_contact(&self, _s: u32, _pos: D::Point, _rot: D::Rot, _facet: &[D::Point]) -> Option<FaceContact<D>> {
        None
    }
}

/// A raw contact found by a narrow phase, before the law is applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawContact<D: Dim> {
    /// Candidate and antagonist bodies; the normal points from j to i.
    pub i: u32,
    pub j: u32,
    /// Feature index for shapes that touch at several points (0 otherwise).
    pub feature: u32,
    pub point: D::Point,
    pub normal: D::Point,
    /// Signed distance (negative: interpenetration).
    pub gap: f64,
    /// Area of contact this point stands for (m² in 3D, m per unit depth in 2D;
    /// 0 for point contacts): what bonded joints scale their strengths with.
    pub area: f64,
}

/// What a narrow phase sees.
pub struct DetectCtx<'a, D: Dim> {
    /// Store of the first kind of the registered pair, and of the second.
    pub a: &'a dyn ShapeStore<D>,
    pub b: &'a dyn ShapeStore<D>,
    pub bodies: &'a Bodies<D>,
    /// Contacts are reported while the gap is below the alert distance.
    pub alert: f64,
}

/// A narrow phase for one pair of shape kinds, called once per batch of candidate
/// pairs: `pairs[k] = [body of kind A, body of kind B]` in the order the detector
/// was registered with.
pub trait PairDetector<D: Dim>: Send + Sync {
    fn detect(&self, ctx: &DetectCtx<'_, D>, pairs: &[[u32; 2]], out: &mut Vec<RawContact<D>>);
}

/// A shape kind: its name and how to make its empty store.
pub struct ShapeKindDef<D: Dim> {
    pub name: &'static str,
    pub new_store: fn() -> Box<dyn ShapeStore<D>>,
}

pub type Aabb2 = Aabb<D2>;
pub type Aabb3 = Aabb<D3>;
pub type MassProps2 = MassProps<D2>;
pub type MassProps3 = MassProps<D3>;
pub type Glyph2 = Glyph<D2>;
pub type Glyph3 = Glyph<D3>;
pub type PointContact2 = PointContact<D2>;
pub type PointContact3 = PointContact<D3>;
pub type FaceContact3 = FaceContact<D3>;
pub type RawContact2 = RawContact<D2>;
pub type RawContact3 = RawContact<D3>;
