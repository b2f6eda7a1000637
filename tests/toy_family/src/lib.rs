//! # A toy body family: point masses
//!
//! Written against the framework's interfaces only ([`nscdd::family`],
//! [`nscdd::dd::Attached`]), in a crate of its own: the proof that a researcher adds
//! a body family without changing the framework or the CLI. A scene's
//! `[[point_masses]]` entries
//!
//! ```toml
//! [[point_masses]]
//! material = "stone"       # a [[materials]] name (the laws with the rigid bodies)
//! mass = 0.5               # kg
//! position = [0.0, 0.21]
//! velocity = [0.0, 0.0]    # optional
//! ```
//!
//! are points of mass m under gravity, touching the world's rigid bodies through
//! their shapes' [`point_contact`](nscdd::shape::ShapeStore::point_contact) (their own
//! detector), with the scene's laws. Each point is one interface entity (its
//! velocity, 2 values): NSCDD glues its copies like a rigid body's, through the one
//! gluing code. One step of a point: V_free = V⁻ + h g, V⁺ = V_free + m⁻¹ Σ_E H_E r_E,
//! x⁺ = x⁻ + h((1 − θ)V⁻ + θV⁺).

mod part;

use nscdd::dd::{Attached, EntityInfo, LocalPart, Rigid2};
use nscdd::dim::D2;
use nscdd::engine::Diverged;
use nscdd::family::{EntryError, FamilyContext, FamilyKind, SceneFamily};
use nscdd::law::{LawInput, LawStep};
use nscdd::norms::natural_map_sq;
use nscdd::registry::{Plugin, Registry};
use nscdd::world::World2;
pub use part::{global, local, rigid_local, PointPart};
use serde::{Deserialize, Serialize};
use std::any::Any;

/// The plugin: the `[[point_masses]]` section of 2D scenes.
pub struct PointMassesPlugin;

impl Plugin for PointMassesPlugin {
    fn name(&self) -> &'static str {
        "toy_point_masses"
    }
    fn build(&self, reg: &mut Registry) {
        reg.add_family::<D2>("point_masses", Box::new(PointMassesKind));
    }
}

// The entry point of the library loaded at run time (tests/loaded.rs).
nscdd::export_plugin!(PointMassesPlugin);

struct PointMassesKind;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Entry {
    material: String,
    mass: f64,
    position: [f64; 2],
    #[serde(default)]
    velocity: [f64; 2],
}

impl FamilyKind<D2> for PointMassesKind {
    fn load(&self, entries: &[toml::Table], cx: &FamilyContext<'_, D2>) -> Result<Box<dyn SceneFamily<D2>>, EntryError> {
        let mut f = PointMasses::default();
        for (i, e) in entries.iter().enumerate() {
            let err = |key: &str, message: String| EntryError {
                index: Some(i),
                key: key.into(),
                message,
            };
            let p = Entry::deserialize(toml::Value::Table(e.clone())).map_err(|x| err("", x.message().to_string()))?;
            let mat = cx.world.materials.iter().position(|m| m.name == p.material);
            let mat = mat.ok_or_else(|| err("material", format!("unknown material `{}`", p.material)))?;
            if !(p.mass > 0.0 && p.mass.is_finite()) {
                return Err(err("mass", format!("must be > 0 and finite, got {}", p.mass)));
            }
            if !p.position.iter().chain(&p.velocity).all(|x| x.is_finite()) {
                return Err(err("position", "position and velocity must be finite".into()));
            }
            f.material.push(mat as u16);
            f.mass.push(p.mass);
            f.x.push(p.position);
            f.v.push(p.velocity);
        }
        f.alert = cx.world.alert;
        f.v_begin = f.v.clone();
        f.v_free = f.v.clone();
        Ok(Box::new(f))
    }
}

/// One contact of a point with a rigid body (the antagonist): the normal points
/// from the body to the point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointContact {
    pub point: u32,
    pub body: u32,
    pub n: [f64; 2],
    /// Lever arms of the body's rotation for the normal and tangential velocity.
    pub arm: [f64; 2],
    pub at: [f64; 2],
    pub gap: f64,
    pub u_target: f64,
    pub mu: f64,
    /// The body's V_free (taken at detection: the world's warm start moves it
    /// before the contacts are built), u_free (local frame) and the impulse r.
    pub body_free: [f64; 3],
    pub u_free: [f64; 2],
    pub r: [f64; 2],
}

/// The point masses of a scene (struct of arrays) and their contacts of the step.
#[derive(Default)]
pub struct PointMasses {
    pub material: Vec<u16>,
    pub mass: Vec<f64>,
    pub x: Vec<[f64; 2]>,
    pub v: Vec<[f64; 2]>,
    pub v_begin: Vec<[f64; 2]>,
    pub v_free: Vec<[f64; 2]>,
    pub alert: f64,
    pub contacts: Vec<PointContact>,
    /// The last step's (point, body) → r, for the warm start.
    prev: Vec<((u32, u32), [f64; 2])>,
}

impl PointMasses {
    /// The point–body pairs within the alert distance (the family's own detector:
    /// every point against every rigid body's bounding box, then its surface).
    fn detect(&mut self, w: &World2) {
        self.prev.clear();
        self.prev.extend(self.contacts.iter().map(|c| ((c.point, c.body), c.r)));
        self.prev.sort_unstable_by_key(|x| x.0);
        self.contacts.clear();
        let alert = self.alert;
        for (p, &x) in self.x.iter().enumerate() {
            for rb in 0..w.bodies.len() {
                let s = w.bodies.shape[rb];
                let store = &w.shapes[s.kind as usize];
                let (pos, rot) = (w.bodies.pos[rb], w.bodies.rot[rb]);
                let a = store.aabb(s.index, pos, rot);
                let inside = (0..2).all(|k| x[k] >= a.min[k] - alert && x[k] <= a.max[k] + alert);
                if !inside || w.law(self.material[p], w.bodies.material[rb]).is_none() {
                    continue;
                }
                let Some(pc) = store.point_contact(s.index, pos, rot, x, [0.0; 2]) else {
                    continue;
                };
                if pc.gap > alert {
                    continue;
                }
                let n = pc.normal;
                let d = [pc.point[0] - pos[0], pc.point[1] - pos[1]];
                let arm = [d[0] * n[1] - d[1] * n[0], d[0] * n[0] + d[1] * n[1]];
                self.contacts.push(PointContact {
                    point: p as u32,
                    body: rb as u32,
                    n,
                    arm,
                    at: pc.point,
                    gap: pc.gap,
                    body_free: w.bodies.vel[rb],
                    ..Default::default()
                });
            }
        }
    }
}

impl Attached<Rigid2> for PointMasses {
    fn after_free_velocity(&mut self, w: &World2) {
        let (h, g) = (w.time.h, w.gravity);
        self.v_begin.clone_from(&self.v);
        for (vf, v) in self.v_free.iter_mut().zip(&self.v) {
            *vf = [v[0] + h * g[0], v[1] + h * g[1]];
        }
        self.detect(w);
    }
    fn build(&mut self, w: &mut World2) {
        let step = LawStep {
            h: w.time.h,
            theta: w.time.theta,
            first: w.step == 0,
        };
        let v_begin = w.velocity_begin();
        for c in self.contacts.iter_mut() {
            let (p, b) = (c.point as usize, c.body as usize);
            let rel = |vp: [f64; 2], vb: [f64; 3]| {
                let (l, r) = (local(c.n, vp), rigid_local(c.n, c.arm, vb));
                [l[0] - r[0], l[1] - r[1]]
            };
            c.u_free = rel(self.v_free[p], c.body_free);
            let input = LawInput {
                gap: c.gap,
                un_begin: rel(self.v_begin[p], v_begin[b])[0],
                un_free: c.u_free[0],
                area: 0.0,
                was_bonded: None,
            };
            let law = w.law(self.material[p], w.bodies.material[b]).expect("detected with a law");
            let t = law.contact(&step, &input).target;
            (c.u_target, c.mu) = (t.u_target, t.mu);
            c.r = match self.prev.binary_search_by_key(&(c.point, c.body), |x| x.0) {
                Ok(k) => self.prev[k].1,
                Err(_) => [0.0; 2],
            };
        }
    }
    fn points(&self, out: &mut Vec<[f64; 3]>) {
        out.extend(self.contacts.iter().map(|c| [c.at[0], c.at[1], 0.0]));
    }
    fn n_entities(&self) -> usize {
        self.x.len()
    }
    fn entity(&self, _e: u32) -> EntityInfo {
        EntityInfo {
            dofs: 2,
            space: 2,
            rho2: 0.0,
            weight: 1.0,
        }
    }
    fn split(&self, _w: &World2, owner: &[u32], copy: &mut dyn FnMut(u32, u32) -> u32) -> Vec<(u32, Box<dyn LocalPart<Rigid2>>)> {
        part::split(self, owner, copy)
    }
    fn write_back(&mut self, _w: &mut World2, parts: &[(u32, &dyn LocalPart<Rigid2>)]) {
        // V⁺ = V_free + m⁻¹ Σ_E H_E r_E
        self.v.clone_from(&self.v_free);
        for (_, p) in parts {
            let Some(p) = p.as_any().downcast_ref::<PointPart>() else {
                continue;
            };
            for (c, &g) in p.contacts.iter().zip(&p.global) {
                let pc = &mut self.contacts[g as usize];
                pc.r = c.r;
                let (pt, f) = (pc.point as usize, global(pc.n, c.r));
                self.v[pt][0] += f[0] / self.mass[pt];
                self.v[pt][1] += f[1] / self.mass[pt];
            }
        }
    }
    fn residual_parts(&self, w: &World2) -> (f64, f64) {
        let (mut f2, mut q2) = (0.0, 0.0);
        for c in &self.contacts {
            let (l, r) = (
                local(c.n, self.v[c.point as usize]),
                rigid_local(c.n, c.arm, w.bodies.vel[c.body as usize]),
            );
            let u = [l[0] - r[0] - c.u_target, l[1] - r[1]];
            f2 += natural_map_sq(&c.r, &u, c.mu);
            let q = [c.u_free[0] - c.u_target, c.u_free[1]];
            q2 += q[0] * q[0] + q[1] * q[1];
        }
        (f2, q2)
    }
}

#[derive(Serialize, Deserialize)]
struct State {
    x: Vec<[f64; 2]>,
    v: Vec<[f64; 2]>,
    /// (point, body, r) of the last step's contacts: the warm start.
    contacts: Vec<(u32, u32, [f64; 2])>,
}

impl SceneFamily<D2> for PointMasses {
    fn section(&self) -> &'static str {
        "point_masses"
    }
    fn describe(&self) -> String {
        format!("{} point masses", self.x.len())
    }
    fn update(&mut self, w: &World2) -> Result<(), Diverged> {
        let (h, th) = (w.time.h, w.time.theta);
        for (p, x) in self.x.iter_mut().enumerate() {
            let (vb, v) = (self.v_begin[p], self.v[p]);
            for k in 0..2 {
                x[k] += h * ((1.0 - th) * vb[k] + th * v[k]);
            }
            if !(x.iter().chain(&v).all(|z| z.is_finite())) {
                return Err(Diverged {
                    step: w.step,
                    body: p as u32,
                    message: format!("point mass {p} has a non-finite state"),
                });
            }
        }
        Ok(())
    }
    fn contacts(&self) -> usize {
        self.contacts.len()
    }
    fn history_columns(&self) -> Vec<String> {
        vec!["kinetic_points".into()]
    }
    fn history_values(&self, out: &mut Vec<f64>) {
        out.push(
            self.mass
                .iter()
                .zip(&self.v)
                .map(|(m, v)| 0.5 * m * (v[0] * v[0] + v[1] * v[1]))
                .sum(),
        );
    }
    fn save_state(&self) -> serde_json::Value {
        let contacts = self.contacts.iter().map(|c| (c.point, c.body, c.r)).collect();
        serde_json::to_value(State {
            x: self.x.clone(),
            v: self.v.clone(),
            contacts,
        })
        .expect("plain data")
    }
    fn load_state(&mut self, state: &serde_json::Value) -> Result<(), String> {
        let s: State = State::deserialize(state).map_err(|e| e.to_string())?;
        if s.x.len() != self.x.len() || s.v.len() != self.v.len() {
            return Err(format!("{} point masses saved, {} in the scene", s.x.len(), self.x.len()));
        }
        (self.x, self.v) = (s.x, s.v);
        self.contacts = s
            .contacts
            .into_iter()
            .map(|(point, body, r)| PointContact {
                point,
                body,
                r,
                ..Default::default()
            })
            .collect();
        Ok(())
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}
