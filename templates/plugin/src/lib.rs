//! # A template nscdd plugin: the 2D `bead` shape
//!
//! A bead is a rigid disk of radius `radius` (m) — the simplest shape, so that what
//! a plugin must provide stands out: a shape store ([`Beads`]: struct-of-arrays
//! parameters, bounding box, mass properties, size, VTK glyph, description), pair
//! detectors called once per batch of candidate pairs ([`BeadBead`],
//! [`BeadHalfPlane`], [`BeadDisk`]), the [`Plugin`] that registers them, and the
//! entry point nscdd loads ([`nscdd::export_plugin!`]).
//!
//! A scene uses it as
//!
//! ```toml
//! [[plugins]]
//! library = "../../target/release/libnscdd_plugin_template.so"
//! [[bodies]]
//! shape = "bead"
//! radius = 0.05
//! material = "stone"
//! position = [0.0, 0.2]
//! ```
//!
//! Detectors see other plugins' shapes only through the `ShapeStore` trait (a
//! built-in disk's radius is its `size`); they never downcast another plugin's store.

use nscdd::dim::D2;
use nscdd::params::{only_keys, positive};
use nscdd::registry::{
    Aabb2, DetectCtx, Glyph2, MassProps2, PairDetector, ParamError, Plugin, RawContact2, Registry, ShapeKindDef, ShapeStore,
};
use std::any::Any;
use std::f64::consts::PI;
use std::sync::Arc;

/// The beads of a scene: one radius per bead (struct of arrays).
#[derive(Default, Clone, Debug)]
pub struct Beads {
    pub radius: Vec<f64>,
}

impl Beads {
    pub const KIND: &'static str = "bead";
}

impl ShapeStore<D2> for Beads {
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
    /// The body's keys beside `shape`, `material`, `position`…: here `radius`.
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
        let mass = density * PI * r * r;
        MassProps2 {
            volume: PI * r * r,
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
}

/// Two round surfaces of centres `xi`, `xj` and radii `ri`, `rj`: gap, normal from j to
/// i, the point half-way across the gap (`None` beyond `alert`).
fn round_pair(i: u32, j: u32, xi: [f64; 2], xj: [f64; 2], ri: f64, rj: f64, alert: f64) -> Option<RawContact2> {
    let d = [xi[0] - xj[0], xi[1] - xj[1]];
    let dist = d[0].hypot(d[1]);
    let gap = dist - ri - rj;
    if gap > alert {
        return None;
    }
    let n = if dist > 0.0 { [d[0] / dist, d[1] / dist] } else { [0.0, 1.0] };
    let s = rj + 0.5 * gap;
    Some(RawContact2 {
        i,
        j,
        feature: 0,
        point: [xj[0] + n[0] * s, xj[1] + n[1] * s],
        normal: n,
        gap,
        area: 0.0,
    })
}

/// Bead–bead: `pairs` are [bead, bead].
pub struct BeadBead;
impl PairDetector<D2> for BeadBead {
    fn detect(&self, cx: &DetectCtx<'_, D2>, pairs: &[[u32; 2]], out: &mut Vec<RawContact2>) {
        let b = cx.bodies;
        for &[p, q] in pairs {
            let (i, j) = (p.min(q) as usize, p.max(q) as usize);
            let (ri, rj) = (cx.a.size(b.shape[i].index), cx.a.size(b.shape[j].index));
            out.extend(round_pair(i as u32, j as u32, b.pos[i], b.pos[j], ri, rj, cx.alert));
        }
    }
}

/// Bead–disk (the built-in `disk`, through its store's `size`): [bead, disk].
pub struct BeadDisk;
impl PairDetector<D2> for BeadDisk {
    fn detect(&self, cx: &DetectCtx<'_, D2>, pairs: &[[u32; 2]], out: &mut Vec<RawContact2>) {
        let b = cx.bodies;
        for &[i, j] in pairs {
            let (iu, ju) = (i as usize, j as usize);
            let (ri, rj) = (cx.a.size(b.shape[iu].index), cx.b.size(b.shape[ju].index));
            out.extend(round_pair(i, j, b.pos[iu], b.pos[ju], ri, rj, cx.alert));
        }
    }
}

/// Bead–half-plane (the built-in `halfplane`: its position on the boundary, its
/// outward normal (−sin θ, cos θ)): [bead, half-plane].
pub struct BeadHalfPlane;
impl PairDetector<D2> for BeadHalfPlane {
    fn detect(&self, cx: &DetectCtx<'_, D2>, pairs: &[[u32; 2]], out: &mut Vec<RawContact2>) {
        let b = cx.bodies;
        for &[i, h] in pairs {
            let (iu, hu) = (i as usize, h as usize);
            let n = [-b.rot[hu].sin(), b.rot[hu].cos()];
            let (x, o) = (b.pos[iu], b.pos[hu]);
            let r = cx.a.size(b.shape[iu].index);
            let gap = (x[0] - o[0]) * n[0] + (x[1] - o[1]) * n[1] - r;
            if gap <= cx.alert {
                let s = r + 0.5 * gap;
                out.push(RawContact2 {
                    i,
                    j: h,
                    feature: 0,
                    point: [x[0] - n[0] * s, x[1] - n[1] * s],
                    normal: n,
                    gap,
                    area: 0.0,
                });
            }
        }
    }
}

/// The plugin: what it adds to nscdd's registry.
pub struct TemplatePlugin;

impl Plugin for TemplatePlugin {
    fn name(&self) -> &'static str {
        "nscdd_plugin_template"
    }
    fn build(&self, reg: &mut Registry) {
        reg.add_shape(ShapeKindDef::<D2> {
            name: Beads::KIND,
            new_store: || Box::new(Beads::default()),
        });
        reg.add_detector::<D2>(Beads::KIND, Beads::KIND, Arc::new(BeadBead));
        reg.add_detector::<D2>(Beads::KIND, "disk", Arc::new(BeadDisk));
        reg.add_detector::<D2>(Beads::KIND, "halfplane", Arc::new(BeadHalfPlane));
    }
}

// The entry point nscdd looks for in the library (`nscdd_plugin_entry`).
nscdd::export_plugin!(TemplatePlugin);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bead_weighs_rho_pi_r2() {
        let mut s = Beads::default();
        let mut p = toml::Table::new();
        p.insert("radius".into(), toml::Value::Float(0.1));
        let k = s.push_params(&p).unwrap();
        let m = s.mass_properties(k, 1000.0);
        assert!((m.mass - 1000.0 * PI * 0.01).abs() < 1e-12);
    }
}
