//! Shape stores of the plugin: disks, walls (thick segments with rounded ends, like
//! LMGC90's JONCx) and half-planes.

use nscdd::dim::D2;
use nscdd::params::{number, only_keys, positive};
use nscdd::registry::{Aabb2, Glyph2, MassProps2, ParamError, PointContact2, ShapeStore};
use std::any::Any;
use std::f64::consts::PI;

/// Disks: key `radius` (m).
#[derive(Default, Clone, Debug)]
pub struct Disks {
    pub radius: Vec<f64>,
}

impl Disks {
    pub const KIND: &'static str = "disk";
}

impl ShapeStore<D2> for Disks {
    fn kind(&self) -> &'static str {
        Self::KIND
    }
    fn len(&self) -> usize {
        self.radius.len()
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
    fn push_params(&mut self, p: &toml::Table) -> Result<u32, ParamError> {
        only_keys(p, &["radius"])?;
        self.radius.push(positive(p, "radius", None)?);
        Ok(self.radius.len() as u32 - 1)
    }
    fn aabb(&self, s: u32, x: [f64; 2], _rot: f64) -> Aabb2 {
        let r = self.radius[s as usize];
        Aabb2 {
            min: [x[0] - r, x[1] - r],
            max: [x[0] + r, x[1] + r],
        }
    }
    /// Area π r², mass ρ π r², inertia m r²/2 (per unit depth).
    fn mass_properties(&self, s: u32, density: f64) -> MassProps2 {
        let r = self.radius[s as usize];
        let area = PI * r * r;
        let mass = density * area;
        MassProps2 {
            volume: area,
            mass,
            inertia: 0.5 * mass * r * r,
        }
    }
    fn size(&self, s: u32) -> f64 {
        self.radius[s as usize]
    }
    fn glyph(&self, s: u32, _x: [f64; 2], _rot: f64) -> Glyph2 {
        Glyph2::Ball(self.radius[s as usize])
    }
    fn describe(&self, s: u32) -> serde_json::Value {
        serde_json::json!({ "radius": self.radius[s as usize] })
    }
    fn point_contact(&self, s: u32, x: [f64; 2], _rot: f64, p: [f64; 2], _hint: [f64; 2]) -> Option<PointContact2> {
        round_contact(x, self.radius[s as usize], p)
    }
}

/// A point against a disk of radius `r` centred at `c` (also the rounded surface of
/// a wall).
fn round_contact(c: [f64; 2], r: f64, p: [f64; 2]) -> Option<PointContact2> {
    let d = [p[0] - c[0], p[1] - c[1]];
    let l = d[0].hypot(d[1]);
    if l < 1e-14 * r.max(1e-300) {
        return None; // the point sits at the centre: no defined normal
    }
    let n = [d[0] / l, d[1] / l];
    Some(PointContact2 {
        gap: l - r,
        normal: n,
        point: [c[0] + r * n[0], c[1] + r * n[1]],
    })
}

/// Walls: a segment of `length` along the body's x axis (rotated by the body's
/// rotation) with `thickness`; the contact surface is the set of points at
/// thickness/2 from the segment, so the ends are rounded.
#[derive(Default, Clone, Debug)]
pub struct Walls {
    pub length: Vec<f64>,
    pub thickness: Vec<f64>,
}

impl Walls {
    pub const KIND: &'static str = "wall";
    /// End points of the centre segment.
    pub fn ends(&self, s: u32, x: [f64; 2], rot: f64) -> ([f64; 2], [f64; 2]) {
        let hl = 0.5 * self.length[s as usize];
        let e = [rot.cos() * hl, rot.sin() * hl];
        ([x[0] - e[0], x[1] - e[1]], [x[0] + e[0], x[1] + e[1]])
    }
}

impl ShapeStore<D2> for Walls {
    fn kind(&self) -> &'static str {
        Self::KIND
    }
    fn len(&self) -> usize {
        self.length.len()
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
    fn push_params(&mut self, p: &toml::Table) -> Result<u32, ParamError> {
        only_keys(p, &["length", "thickness"])?;
        self.length.push(positive(p, "length", None)?);
        self.thickness.push(positive(p, "thickness", None)?);
        Ok(self.length.len() as u32 - 1)
    }
    fn aabb(&self, s: u32, x: [f64; 2], rot: f64) -> Aabb2 {
        let (a, b) = self.ends(s, x, rot);
        let t = 0.5 * self.thickness[s as usize];
        Aabb2 {
            min: [a[0].min(b[0]) - t, a[1].min(b[1]) - t],
            max: [a[0].max(b[0]) + t, a[1].max(b[1]) + t],
        }
    }
    /// A rectangle length × thickness: m = ρ L T, I = m (L² + T²)/12.
    fn mass_properties(&self, s: u32, density: f64) -> MassProps2 {
        let (l, t) = (self.length[s as usize], self.thickness[s as usize]);
        let mass = density * l * t;
        MassProps2 {
            volume: l * t,
            mass,
            inertia: mass * (l * l + t * t) / 12.0,
        }
    }
    fn size(&self, s: u32) -> f64 {
        0.5 * self.thickness[s as usize]
    }
    fn glyph(&self, s: u32, x: [f64; 2], rot: f64) -> Glyph2 {
        let (a, b) = self.ends(s, x, rot);
        Glyph2::Segment(a, b, self.thickness[s as usize])
    }
    fn describe(&self, s: u32) -> serde_json::Value {
        serde_json::json!({ "length": self.length[s as usize], "thickness": self.thickness[s as usize] })
    }
    fn is_grain(&self) -> bool {
        false
    }
    /// The closest point of the centre segment, then as for a disk of radius T/2.
    fn point_contact(&self, s: u32, x: [f64; 2], rot: f64, p: [f64; 2], _hint: [f64; 2]) -> Option<PointContact2> {
        let (a, b) = self.ends(s, x, rot);
        let ab = [b[0] - a[0], b[1] - a[1]];
        let t = (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / (ab[0] * ab[0] + ab[1] * ab[1])).clamp(0.0, 1.0);
        round_contact([a[0] + t * ab[0], a[1] + t * ab[1]], 0.5 * self.thickness[s as usize], p)
    }
}

/// Half-planes: the body's position is a point of the boundary and its rotation θ
/// turns the outward normal (−sin θ, cos θ): θ = 0 is a floor (solid below). They are
/// meant to be fixed or driven by velocity; their nominal mass is density × 1 m².
/// Optional key `display_length` (m, default 1) sets the drawn length in VTK.
#[derive(Default, Clone, Debug)]
pub struct HalfPlanes {
    pub display_length: Vec<f64>,
}

impl HalfPlanes {
    pub const KIND: &'static str = "halfplane";
    pub fn normal(rot: f64) -> [f64; 2] {
        [-rot.sin(), rot.cos()]
    }
}

impl ShapeStore<D2> for HalfPlanes {
    fn kind(&self) -> &'static str {
        Self::KIND
    }
    fn len(&self) -> usize {
        self.display_length.len()
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
    fn push_params(&mut self, p: &toml::Table) -> Result<u32, ParamError> {
        only_keys(p, &["display_length"])?;
        self.display_length.push(positive(p, "display_length", Some(1.0))?);
        let _ = number;
        Ok(self.display_length.len() as u32 - 1)
    }
    fn aabb(&self, _s: u32, x: [f64; 2], rot: f64) -> Aabb2 {
        let n = Self::normal(rot);
        let inf = f64::INFINITY;
        // axis-aligned planes keep one finite face (used for box samples)
        let mut b = Aabb2 {
            min: [-inf, -inf],
            max: [inf, inf],
        };
        if n[0].abs() < 1e-12 {
            if n[1] > 0.0 {
                b.max[1] = x[1]
            } else {
                b.min[1] = x[1]
            }
        } else if n[1].abs() < 1e-12 {
            if n[0] > 0.0 {
                b.max[0] = x[0]
            } else {
                b.min[0] = x[0]
            }
        }
        b
    }
    fn mass_properties(&self, _s: u32, density: f64) -> MassProps2 {
        MassProps2 {
            volume: 1.0,
            mass: density,
            inertia: density / 6.0,
        }
    }
    fn size(&self, _s: u32) -> f64 {
        f64::INFINITY
    }
    fn glyph(&self, s: u32, x: [f64; 2], rot: f64) -> Glyph2 {
        let n = Self::normal(rot);
        let hl = 0.5 * self.display_length[s as usize];
        let t = [n[1] * hl, -n[0] * hl];
        let d = 0.02 * hl;
        Glyph2::Polygon(vec![
            [x[0] - t[0], x[1] - t[1]],
            [x[0] + t[0], x[1] + t[1]],
            [x[0] + t[0] - d * n[0], x[1] + t[1] - d * n[1]],
            [x[0] - t[0] - d * n[0], x[1] - t[1] - d * n[1]],
        ])
    }
    fn describe(&self, _s: u32) -> serde_json::Value {
        serde_json::json!({})
    }
    fn is_grain(&self) -> bool {
        false
    }
    fn point_contact(&self, _s: u32, x: [f64; 2], rot: f64, p: [f64; 2], _hint: [f64; 2]) -> Option<PointContact2> {
        let n = Self::normal(rot);
        let gap = (p[0] - x[0]) * n[0] + (p[1] - x[1]) * n[1];
        Some(PointContact2 {
            gap,
            normal: n,
            point: [p[0] - gap * n[0], p[1] - gap * n[1]],
        })
    }
}
