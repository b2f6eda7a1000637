//! The polygon store: convex polygons held about their centroid (struct of arrays:
//! the vertices and edge normals of all polygons in two flat vectors, each
//! polygon's range in `first`), their convex hull, area and polar moment.

use nscdd::dim::D2;
use nscdd::params::{array, count, only_keys, positive};
use nscdd::registry::{Aabb2, Glyph2, MassProps2, ParamError, PointContact2, ShapeStore};
use std::any::Any;
use std::f64::consts::PI;

/// Most vertices a polygon may have (contact feature ids hold 10 bits per index).
pub const MAX_VERTICES: usize = 256;

pub(crate) fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}
pub(crate) fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
pub(crate) fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
/// Rotation by the angle whose cosine and sine are `cs`.
#[inline]
pub(crate) fn turn(cs: [f64; 2], v: [f64; 2]) -> [f64; 2] {
    [cs[0] * v[0] - cs[1] * v[1], cs[1] * v[0] + cs[0] * v[1]]
}

/// The convex hull of `points`, counter-clockwise, without collinear points
/// (Andrew's monotone chain; a dozen lines, so no crate for it).
pub fn convex_hull(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut p: Vec<[f64; 2]> = points.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let mut h: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = h.len();
        // the lower chain left to right, then the upper chain right to left
        for k in 0..p.len() {
            let q = if pass == 0 { p[k] } else { p[p.len() - 1 - k] };
            while h.len() >= start + 2 && cross(sub(h[h.len() - 1], h[h.len() - 2]), sub(q, h[h.len() - 2])) <= 0.0 {
                h.pop();
            }
            h.push(q);
        }
        h.pop(); // the last point starts the other chain
    }
    h
}

/// Area, centroid and polar moment about the centroid per unit density of a
/// counter-clockwise polygon.
pub fn moments(v: &[[f64; 2]]) -> (f64, [f64; 2], f64) {
    let (mut a, mut cx, mut cy, mut j) = (0.0, 0.0, 0.0, 0.0);
    let o = v[0]; // about the first vertex, for round-off
    for k in 0..v.len() {
        let (p, q) = (sub(v[k], o), sub(v[(k + 1) % v.len()], o));
        let c = cross(p, q);
        a += 0.5 * c;
        cx += c * (p[0] + q[0]) / 6.0;
        cy += c * (p[1] + q[1]) / 6.0;
        j += c * (dot(p, p) + dot(p, q) + dot(q, q)) / 12.0;
    }
    let c = [cx / a, cy / a];
    // parallel axes: J_o = J_c + A |c|²
    (a, [o[0] + c[0], o[1] + c[1]], j - a * dot(c, c))
}

/// Convex polygons. A body gives one of: `vertices` = [[x, y], …] (m, in the
/// body's frame: the convex hull is taken, at most 256 points), `sides` with
/// `radius` (a regular polygon of circumradius `radius`, one edge at the bottom),
/// or `size` = [w, h] (a rectangle). The body's position becomes the centroid.
#[derive(Clone, Debug)]
pub struct Polygons {
    /// Polygon s owns `vertices[first[s]..first[s + 1]]` and the same `normals`.
    pub first: Vec<u32>,
    /// Vertices about the centroid, counter-clockwise.
    pub vertices: Vec<[f64; 2]>,
    /// Outward unit normal of edge k (from vertex k to vertex k + 1).
    pub normals: Vec<[f64; 2]>,
    pub area: Vec<f64>,
    /// Polar moment about the centroid per unit density (m⁴).
    pub polar: Vec<f64>,
    /// Distance of the farthest vertex from the centroid.
    pub radius: Vec<f64>,
    /// Where the centroid lies in the frame the vertices were given in.
    pub centroid: Vec<[f64; 2]>,
}

impl Default for Polygons {
    fn default() -> Self {
        Polygons {
            first: vec![0],
            vertices: vec![],
            normals: vec![],
            area: vec![],
            polar: vec![],
            radius: vec![],
            centroid: vec![],
        }
    }
}

impl Polygons {
    pub const KIND: &'static str = "polygon";

    /// Vertices of shape s (about its centroid) and their edge normals.
    #[inline]
    pub fn shape(&self, s: u32) -> (&[[f64; 2]], &[[f64; 2]]) {
        let (a, b) = (self.first[s as usize] as usize, self.first[s as usize + 1] as usize);
        (&self.vertices[a..b], &self.normals[a..b])
    }

    /// Stores the convex hull of `points` (any frame); returns its index.
    pub fn push_points(&mut self, points: &[[f64; 2]]) -> Result<u32, String> {
        if points.len() > MAX_VERTICES {
            return Err(format!("at most {MAX_VERTICES} vertices, got {}", points.len()));
        }
        if points.iter().flatten().any(|x| !x.is_finite()) {
            return Err("vertices must be finite".into());
        }
        let h = convex_hull(points);
        if h.len() < 3 {
            return Err("the polygon has no area: fewer than 3 distinct, non-collinear vertices".into());
        }
        let (area, c, polar) = moments(&h);
        let scale = h.iter().map(|p| dot(sub(*p, c), sub(*p, c)).sqrt()).fold(0.0, f64::max);
        if !(area > 1e-12 * scale * scale && area.is_finite()) {
            return Err(format!("the polygon has no area ({area}): its vertices are (nearly) collinear"));
        }
        for k in 0..h.len() {
            let e = sub(h[(k + 1) % h.len()], h[k]);
            let l = dot(e, e).sqrt();
            self.normals.push([e[1] / l, -e[0] / l]);
            self.vertices.push(sub(h[k], c));
        }
        self.first.push(self.vertices.len() as u32);
        self.area.push(area);
        self.polar.push(polar);
        self.radius.push(scale);
        self.centroid.push(c);
        Ok(self.area.len() as u32 - 1)
    }

    /// World vertices of shape s at a pose (appended to `out` after clearing it).
    pub fn world_vertices(&self, s: u32, x: [f64; 2], rot: f64, out: &mut Vec<[f64; 2]>) {
        let cs = [rot.cos(), rot.sin()];
        out.clear();
        out.extend(self.shape(s).0.iter().map(|v| {
            let r = turn(cs, *v);
            [x[0] + r[0], x[1] + r[1]]
        }));
    }
}

/// The vertices of a regular polygon of `n` sides and circumradius `r`, the first
/// edge at the bottom (horizontal), turned by `phase`.
pub fn regular(n: usize, r: f64, phase: f64) -> Vec<[f64; 2]> {
    (0..n)
        .map(|k| {
            let a = -0.5 * PI - PI / n as f64 + 2.0 * PI * k as f64 / n as f64 + phase;
            [r * a.cos(), r * a.sin()]
        })
        .collect()
}

/// The polygon a body's keys describe (its vertices in the body's frame).
fn points_of(p: &toml::Table) -> Result<Vec<[f64; 2]>, ParamError> {
    only_keys(p, &["vertices", "sides", "radius", "size"])?;
    let given = ["vertices", "sides", "size"].iter().filter(|k| p.contains_key(**k)).count();
    if given != 1 {
        return Err(ParamError::new(
            "vertices",
            "a polygon needs exactly one of `vertices`, `sides` (with `radius`) or `size`",
        ));
    }
    if p.contains_key("radius") && !p.contains_key("sides") {
        return Err(ParamError::new("radius", "only with `sides` (a regular polygon)"));
    }
    if p.contains_key("sides") {
        let n = count(p, "sides", None)? as usize;
        if !(3..=MAX_VERTICES).contains(&n) {
            return Err(ParamError::new("sides", format!("must be in 3..={MAX_VERTICES}, got {n}")));
        }
        return Ok(regular(n, positive(p, "radius", None)?, 0.0));
    }
    if p.contains_key("size") {
        let [w, h] = array::<2>(p, "size", None)?;
        if !(w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()) {
            return Err(ParamError::new("size", "2 positive sizes [w, h]"));
        }
        return Ok(vec![
            [-0.5 * w, -0.5 * h],
            [0.5 * w, -0.5 * h],
            [0.5 * w, 0.5 * h],
            [-0.5 * w, 0.5 * h],
        ]);
    }
    let bad = || ParamError::new("vertices", "a list of at least 3 points [x, y]");
    let arr = p.get("vertices").and_then(|v| v.as_array()).ok_or_else(bad)?;
    let mut pts = Vec::with_capacity(arr.len());
    for v in arr {
        let a = v.as_array().filter(|a| a.len() == 2).ok_or_else(bad)?;
        let num = |x: &toml::Value| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)).ok_or_else(bad);
        pts.push([num(&a[0])?, num(&a[1])?]);
    }
    Ok(pts)
}

impl ShapeStore<D2> for Polygons {
    fn kind(&self) -> &'static str {
        Self::KIND
    }
    fn len(&self) -> usize {
        self.area.len()
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
    fn push_params(&mut self, p: &toml::Table) -> Result<u32, ParamError> {
        let pts = points_of(p)?;
        self.push_points(&pts).map_err(|m| ParamError::new("vertices", m))
    }
    fn aabb(&self, s: u32, x: [f64; 2], rot: f64) -> Aabb2 {
        let cs = [rot.cos(), rot.sin()];
        let mut b = Aabb2 {
            min: [f64::INFINITY; 2],
            max: [f64::NEG_INFINITY; 2],
        };
        for v in self.shape(s).0 {
            let r = turn(cs, *v);
            for k in 0..2 {
                b.min[k] = b.min[k].min(x[k] + r[k]);
                b.max[k] = b.max[k].max(x[k] + r[k]);
            }
        }
        b
    }
    /// Area A (shoelace), mass ρA, inertia ρJ about the centroid (per unit depth).
    fn mass_properties(&self, s: u32, density: f64) -> MassProps2 {
        let a = self.area[s as usize];
        MassProps2 {
            volume: a,
            mass: density * a,
            inertia: density * self.polar[s as usize],
        }
    }
    fn size(&self, s: u32) -> f64 {
        self.radius[s as usize]
    }
    fn glyph(&self, s: u32, x: [f64; 2], rot: f64) -> Glyph2 {
        let mut w = vec![];
        self.world_vertices(s, x, rot, &mut w);
        Glyph2::Polygon(w)
    }
    fn describe(&self, s: u32) -> serde_json::Value {
        serde_json::json!({ "vertices": self.shape(s).0, "area": self.area[s as usize] })
    }
    fn principal_frame(&self, s: u32) -> ([f64; 2], f64) {
        (self.centroid[s as usize], 0.0)
    }
    /// A point (a boundary node of a deformable body) against the polygon: the
    /// closest point of its boundary, or, inside, the nearest edge.
    fn point_contact(&self, s: u32, x: [f64; 2], rot: f64, p: [f64; 2], _hint: [f64; 2]) -> Option<PointContact2> {
        let (v, n) = self.shape(s);
        let cs = [rot.cos(), -rot.sin()];
        let q = turn(cs, sub(p, x)); // p in the polygon's frame
        let (gap, nl, cl) = crate::detect::closest_boundary(v, n, q);
        let back = [cs[0], -cs[1]];
        let (nw, cw) = (turn(back, nl), turn(back, cl));
        Some(PointContact2 {
            gap,
            normal: nw,
            point: [x[0] + cw[0], x[1] + cw[1]],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_drops_inner_and_collinear_points_and_turns_counter_clockwise() {
        let h = convex_hull(&[[0.0, 0.0], [1.0, 0.0], [0.5, 0.0], [1.0, 1.0], [0.5, 0.5], [0.0, 1.0]]);
        assert_eq!(h, vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    }

    #[test]
    fn a_rectangle_has_area_wh_and_polar_moment_a_w2_h2_over_12() {
        let mut s = Polygons::default();
        let k = s.push_points(&[[1.0, 1.0], [3.0, 1.0], [3.0, 2.0], [1.0, 2.0]]).unwrap();
        let (w, h) = (2.0, 1.0);
        assert!((s.area[0] - w * h).abs() < 1e-14);
        assert!((s.polar[0] - w * h * (w * w + h * h) / 12.0).abs() < 1e-14);
        assert_eq!(s.centroid[0], [2.0, 1.5]);
        assert_eq!(s.shape(k).1[0], [0.0, -1.0], "the bottom edge faces down");
    }

    #[test]
    fn a_regular_polygon_tends_to_a_disk() {
        let mut s = Polygons::default();
        s.push_points(&regular(256, 1.0, 0.3)).unwrap();
        assert!((s.area[0] - PI).abs() < 1e-3 && (s.polar[0] - 0.5 * PI).abs() < 1e-3);
        assert!(s.centroid[0][0].abs() < 1e-12 && s.centroid[0][1].abs() < 1e-12);
    }
}
