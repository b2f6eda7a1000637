//! The polyhedron store: each shape is held in its principal frame (centroid at
//! the origin, principal axes along the body axes), with its faces, outward
//! normals and edges for detection.

use crate::hull::{hull, moments, norm, principal, quat_of, sub, Hull};
use nscdd::dim::rotation::rotate;
use nscdd::dim::D3;
use nscdd::params::only_keys;
use nscdd::registry::ParamError;
use nscdd::registry::{Aabb3, Glyph3, MassProps3, PointContact3, ShapeStore};
use std::any::Any;

/// One convex polyhedron in its principal frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Poly {
    pub vertices: Vec<[f64; 3]>,
    pub faces: Vec<Vec<u32>>,
    pub normals: Vec<[f64; 3]>,
    /// Unique edges (vertex pairs).
    pub edges: Vec<[u32; 2]>,
    /// The two faces that meet at each edge.
    pub edge_faces: Vec<[u32; 2]>,
    pub volume: f64,
    /// Principal moments of inertia per unit density.
    pub inertia: [f64; 3],
    /// Distance of the farthest vertex from the centroid.
    pub radius: f64,
}

impl Poly {
    /// World coordinates of the vertices at a pose.
    pub fn world_vertices(&self, x: [f64; 3], q: [f64; 4], out: &mut Vec<[f64; 3]>) {
        out.clear();
        out.extend(self.vertices.iter().map(|v| {
            let r = rotate(q, *v);
            [x[0] + r[0], x[1] + r[1], x[2] + r[2]]
        }));
    }

    /// A polyhedron from the hull of `points` given in any frame; also returns
    /// the principal frame in that frame (centroid, quaternion).
    pub fn from_points(points: &[[f64; 3]]) -> Result<(Poly, [f64; 3], [f64; 4]), String> {
        let h = hull(points)?;
        let (volume, c, second) = moments(&h);
        if !(volume > 0.0 && volume.is_finite()) {
            return Err(format!(
                "the polyhedron has no volume ({volume}): its vertices are (nearly) coplanar"
            ));
        }
        let (inertia, r) = principal(&second);
        // coordinates in the principal frame: Rᵀ (x − c)
        let to_local = |p: [f64; 3]| {
            let d = sub(p, c);
            [0, 1, 2].map(|k| r[0][k] * d[0] + r[1][k] * d[1] + r[2][k] * d[2])
        };
        let vertices: Vec<[f64; 3]> = h.vertices.iter().map(|p| to_local(*p)).collect();
        let normals: Vec<[f64; 3]> = h
            .normals
            .iter()
            .map(|n| [0, 1, 2].map(|k| r[0][k] * n[0] + r[1][k] * n[1] + r[2][k] * n[2]))
            .collect();
        let (mut edges, mut edge_faces): (Vec<[u32; 2]>, Vec<[u32; 2]>) = (vec![], vec![]);
        for (fi, f) in h.faces.iter().enumerate() {
            for q in 0..f.len() {
                let (a, b) = (f[q], f[(q + 1) % f.len()]);
                let e = [a.min(b), a.max(b)];
                match edges.iter().position(|x| *x == e) {
                    Some(k) => edge_faces[k] = [edge_faces[k][0], fi as u32],
                    None => {
                        edges.push(e);
                        edge_faces.push([fi as u32, u32::MAX]);
                    }
                }
            }
        }
        if edge_faces.iter().any(|f| f[1] == u32::MAX) {
            return Err("the hull is not closed (an edge with one face)".into());
        }
        let radius = vertices.iter().map(|v| norm(*v)).fold(0.0, f64::max);
        let Hull { faces, .. } = h;
        Ok((
            Poly {
                vertices,
                faces,
                normals,
                edges,
                edge_faces,
                volume,
                inertia,
                radius,
            },
            c,
            quat_of(&r),
        ))
    }
}

/// Convex polyhedra: key `vertices` = [[x, y, z], …] (m) in the body's frame as
/// written in the scene; the body's position becomes its centroid and its
/// orientation its principal axes (`final.json` reports those).
#[derive(Default, Clone, Debug)]
pub struct Polyhedra {
    pub shapes: Vec<Poly>,
    /// Principal frame of each shape in the frame it was given in.
    pub frames: Vec<([f64; 3], [f64; 4])>,
}

impl Polyhedra {
    pub const KIND: &'static str = "polyhedron";

    /// Stores a polyhedron given by points in some frame; returns its index.
    pub fn push_points(&mut self, points: &[[f64; 3]]) -> Result<u32, String> {
        let (p, c, q) = Poly::from_points(points)?;
        self.shapes.push(p);
        self.frames.push((c, q));
        Ok(self.shapes.len() as u32 - 1)
    }

    /// World coordinates of the vertices of shape s at a pose.
    pub fn world_vertices(&self, s: u32, x: [f64; 3], q: [f64; 4], out: &mut Vec<[f64; 3]>) {
        self.shapes[s as usize].world_vertices(x, q, out);
    }
}

impl ShapeStore<D3> for Polyhedra {
    fn kind(&self) -> &'static str {
        Self::KIND
    }
    fn len(&self) -> usize {
        self.shapes.len()
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
    fn push_params(&mut self, p: &toml::Table) -> Result<u32, ParamError> {
        only_keys(p, &["vertices"])?;
        let bad = || ParamError::new("vertices", "a list of at least 4 points [x, y, z]");
        let arr = p.get("vertices").and_then(|v| v.as_array()).ok_or_else(bad)?;
        let mut pts = vec![];
        for v in arr {
            let a = v.as_array().filter(|a| a.len() == 3).ok_or_else(bad)?;
            let mut q = [0.0; 3];
            for (k, x) in a.iter().enumerate() {
                q[k] = x.as_float().or_else(|| x.as_integer().map(|i| i as f64)).ok_or_else(bad)?;
            }
            pts.push(q);
        }
        if pts.len() < 4 {
            return Err(bad());
        }
        self.push_points(&pts).map_err(|m| ParamError::new("vertices", m))
    }
    fn aabb(&self, s: u32, x: [f64; 3], q: [f64; 4]) -> Aabb3 {
        let mut a = Aabb3 {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        };
        for v in &self.shapes[s as usize].vertices {
            let r = rotate(q, *v);
            for k in 0..3 {
                a.min[k] = a.min[k].min(x[k] + r[k]);
                a.max[k] = a.max[k].max(x[k] + r[k]);
            }
        }
        a
    }
    fn mass_properties(&self, s: u32, density: f64) -> MassProps3 {
        let p = &self.shapes[s as usize];
        MassProps3 {
            volume: p.volume,
            mass: density * p.volume,
            inertia: p.inertia.map(|i| density * i),
        }
    }
    fn size(&self, s: u32) -> f64 {
        self.shapes[s as usize].radius
    }
    fn glyph(&self, s: u32, x: [f64; 3], q: [f64; 4]) -> Glyph3 {
        let p = &self.shapes[s as usize];
        let mut w = vec![];
        self.world_vertices(s, x, q, &mut w);
        Glyph3::Faces(p.faces.iter().map(|f| f.iter().map(|&v| w[v as usize]).collect()).collect())
    }
    fn describe(&self, s: u32) -> serde_json::Value {
        serde_json::json!({ "vertices": self.shapes[s as usize].vertices, "volume": self.shapes[s as usize].volume })
    }
    fn is_grain(&self) -> bool {
        true
    }
    fn principal_frame(&self, s: u32) -> ([f64; 3], [f64; 4]) {
        self.frames[s as usize]
    }
    /// A boundary node of a deformable body against the block: the closest point
    /// of the block's surface (a block resting on a soil mesh finer than itself
    /// meets the mesh's nodes under it).
    fn point_contact(&self, s: u32, x: [f64; 3], q: [f64; 4], p: [f64; 3], hint: [f64; 3]) -> Option<PointContact3> {
        let poly = &self.shapes[s as usize];
        let mut wv = [[0.0; 3]; 64];
        for (k, v) in poly.vertices.iter().enumerate() {
            let r = rotate(q, *v);
            wv[k] = [x[0] + r[0], x[1] + r[1], x[2] + r[2]];
        }
        let (point, normal, gap) = crate::detect::closest_surface(poly, &wv[..poly.vertices.len()], q, p, hint)?;
        Some(PointContact3 { gap, normal, point })
    }
}

/// Face f of a polyhedron at a pose: world polygon and outward normal.
pub fn world_face(p: &Poly, wv: &[[f64; 3]], q: [f64; 4], f: usize, out: &mut Vec<[f64; 3]>) -> [f64; 3] {
    out.clear();
    out.extend(p.faces[f].iter().map(|&v| wv[v as usize]));
    rotate(q, p.normals[f])
}

/// Unit vector of a non-zero vector, or `None`.
pub fn unit(a: [f64; 3]) -> Option<[f64; 3]> {
    let l = norm(a);
    (l > 1e-300).then(|| a.map(|x| x / l))
}
