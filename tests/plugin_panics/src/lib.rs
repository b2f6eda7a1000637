//! A plugin with a `fragile` 2D shape (a disk of `radius`) whose detector against
//! half-planes panics once its bead comes within `panic_below` of the floor, and a
//! `brittle` law that panics at its first contact, and a body family
//! (`[[fragile_family]]`) that panics while it loads: nscdd must report `plugin
//! nscdd_plugin_panics: …` and stop, keeping what was written.

use nscdd::dim::D2;
use nscdd::params::{number, only_keys, positive};
use nscdd::registry::*;
use std::any::Any;
use std::sync::Arc;

#[derive(Default)]
struct Fragile {
    radius: Vec<f64>,
    panic_below: Vec<f64>,
}

impl ShapeStore<D2> for Fragile {
    fn kind(&self) -> &'static str {
        "fragile"
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
        only_keys(p, &["radius", "panic_below"])?;
        self.radius.push(positive(p, "radius", None)?);
        self.panic_below.push(number(p, "panic_below", Some(-1.0))?);
        Ok(self.radius.len() as u32 - 1)
    }
    fn aabb(&self, s: u32, x: [f64; 2], _rot: f64) -> Aabb2 {
        let r = self.radius[s as usize];
        Aabb2 {
            min: [x[0] - r, x[1] - r],
            max: [x[0] + r, x[1] + r],
        }
    }
    fn mass_properties(&self, s: u32, density: f64) -> MassProps2 {
        let r = self.radius[s as usize];
        let m = density * std::f64::consts::PI * r * r;
        MassProps2 {
            volume: m / density,
            mass: m,
            inertia: 0.5 * m * r * r,
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

struct FragileHalfPlane;
impl PairDetector<D2> for FragileHalfPlane {
    fn detect(&self, cx: &DetectCtx<'_, D2>, pairs: &[[u32; 2]], out: &mut Vec<RawContact2>) {
        let store = cx.a.as_any().downcast_ref::<Fragile>().expect("fragile store");
        let b = cx.bodies;
        for &[i, h] in pairs {
            let s = b.shape[i as usize].index as usize;
            let gap = b.pos[i as usize][1] - b.pos[h as usize][1] - store.radius[s];
            if gap < store.panic_below[s] {
                panic!("the fragile bead broke at gap {gap}");
            }
            if gap <= cx.alert {
                let x = b.pos[i as usize];
                out.push(RawContact2 {
                    i,
                    j: h,
                    feature: 0,
                    point: [x[0], x[1] - store.radius[s] - 0.5 * gap],
                    normal: [0.0, 1.0],
                    gap,
                    area: 0.0,
                });
            }
        }
    }
}

/// Fragile beads never touch one another (the scenes have one).
struct Never;
impl PairDetector<D2> for Never {
    fn detect(&self, _cx: &DetectCtx<'_, D2>, _pairs: &[[u32; 2]], _out: &mut Vec<RawContact2>) {}
}

/// A law that breaks at the first contact it is given.
#[derive(Debug)]
struct Brittle;
impl nscdd::law::Law for Brittle {
    fn contacts(
        &self,
        _step: &nscdd::law::LawStep,
        inputs: &[nscdd::law::LawInput],
        _t: &mut [nscdd::model::Target],
        _j: &mut [nscdd::dim::joint::Joint],
    ) {
        if !inputs.is_empty() {
            panic!("the brittle law broke on {} contacts", inputs.len());
        }
    }
}

/// A body family (`[[fragile_family]]`) that breaks while its scene loads.
struct FragileFamily;
impl nscdd::family::FamilyKind<D2> for FragileFamily {
    fn load(
        &self,
        entries: &[toml::Table],
        _cx: &nscdd::family::FamilyContext<'_, D2>,
    ) -> Result<Box<dyn nscdd::family::SceneFamily<D2>>, nscdd::family::EntryError> {
        panic!("the fragile family broke loading {} entries", entries.len())
    }
}

struct Panics;
impl Plugin for Panics {
    fn name(&self) -> &'static str {
        "nscdd_plugin_panics"
    }
    fn build(&self, reg: &mut Registry) {
        reg.add_shape(ShapeKindDef::<D2> {
            name: "fragile",
            new_store: || Box::new(Fragile::default()),
        });
        reg.add_detector::<D2>("fragile", "halfplane", Arc::new(FragileHalfPlane));
        reg.add_detector::<D2>("fragile", "fragile", Arc::new(Never));
        reg.add_law(nscdd::law::LawDef {
            name: "brittle",
            parse: |t| {
                nscdd::params::only_keys(t, &[])?;
                Ok(Arc::new(Brittle))
            },
        });
        reg.add_family::<D2>("fragile_family", Box::new(FragileFamily));
    }
}

nscdd::export_plugin!(Panics);
