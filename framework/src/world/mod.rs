//! A loaded scene and its state (2D or 3D): bodies, shapes, materials, laws, drives
//! and the contact set. Built by [`crate::scene`], advanced by [`crate::engine`].

pub mod bulk;
pub mod held;

use crate::detect::{Detector, DetectorTable};
use crate::dim::{Dim, Vector, D2, D3};
use crate::drive::BodyDrive;
use crate::law::{Law, LawBatches};
use crate::model::{Bodies, BodyIds, ContactKey, Contacts};
use crate::shape::{Aabb, RawContact, ShapeStore};
use crate::solver::SolverSettings;
use std::sync::Arc;

/// A material: its name and density (kg/m³; per unit depth in 2D).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Material {
    pub name: String,
    pub density: f64,
}

/// Time integration settings.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct TimeSettings {
    /// Step h (s).
    pub h: f64,
    /// θ of the θ-method, in [½, 1].
    pub theta: f64,
    /// Number of steps to run.
    pub steps: u64,
}

/// The walls bounding a box sample (x−, x+, y−, y+ and in 3D z−, z+): the solid
/// fraction, the stresses, ε1 (along the last axis) and the pressure drives.
#[derive(Clone, Debug, PartialEq)]
pub struct BoxWalls {
    /// Wall bodies, 2N used.
    pub walls: [u32; 6],
    /// ε1 is measured from the box height at this time.
    pub strain_from: f64,
}

impl BoxWalls {
    /// Which wall body b is (0..2N), if any.
    pub fn wall_of(&self, b: usize, n: usize) -> Option<usize> {
        self.walls[..2 * n].iter().position(|&x| x as usize == b)
    }
}

/// The scene in memory.
pub struct World<D: Dim> {
    /// The bodies, by slot.
    pub bodies: Bodies<D>,
    /// Slot ↔ global id (the identity in one process; [`crate::model::ids`]).
    /// Contact keys and everything leaving the world use global ids.
    pub ids: BodyIds,
    /// Optional user names of bodies (for outputs), by body id.
    pub names: Vec<Option<String>>,
    /// One store per shape kind used by the scene; `bodies.shape[b].kind` indexes it.
    pub shapes: Vec<Box<dyn ShapeStore<D>>>,
    pub materials: Vec<Material>,
    /// Law of each material pair, `laws[ma * nm + mb]`.
    pub laws: Vec<Option<Arc<dyn Law>>>,
    pub drives: Vec<BodyDrive>,
    /// Which bodies are fixed (no degree of freedom ever moves).
    pub fixed: Vec<bool>,
    pub gravity: D::Point,
    pub time: TimeSettings,
    pub solver: SolverSettings,
    /// Alert distance of the detection.
    pub alert: f64,
    pub box_walls: Option<BoxWalls>,
    /// Box height (along the last axis) when ε1 starts (set by the engine).
    pub box_h0: Option<f64>,
    pub detectors: DetectorTable<D>,
    /// Current time and completed steps.
    pub t: f64,
    pub step: u64,
    /// The last step's contacts (impulses kept for the warm start).
    pub contacts: Contacts<D>,
    /// Contact impulse resultant per body over the last step, Σ ±H r (N·s).
    pub reaction: Vec<D::Twist>,
    /// Shares of the contacts' elastic energy that the world keeps, set by body
    /// families that take the rest (a continuum region's overlap band): each step,
    /// every share gives a weight w ∈ (0, 1] per contact (from its bodies and
    /// point) and a compliant contact's stiffness and damping are multiplied by
    /// the product, i.e. its compliance c divided by it. Empty: w = 1.
    pub contact_shares: Vec<ContactShare<D>>,
    /// The whole scene's static sums, kept before the world first drops a body
    /// ([`held`]); `None`: computed from the bodies.
    pub whole: Option<held::WholeScene>,
    pub(crate) scratch: Scratch<D>,
}

/// A share of the contacts' stiffness ([`World::contact_shares`]): multiplies
/// `weight[a]` by the world's share of contact a of key `keys[a]` (its bodies'
/// global ids) at `point[a]`; one call per step for all the contacts.
pub type ContactShare<D> = Arc<dyn Fn(&[crate::model::ContactKey], &[<D as Dim>::Point], &mut [f64]) + Send + Sync>;

/// The 2D world.
pub type World2 = World<D2>;
/// The 3D world.
pub type World3 = World<D3>;

/// Buffers reused from step to step.
pub(crate) struct Scratch<D: Dim> {
    pub detector: Detector<D>,
    pub raw: Vec<RawContact<D>>,
    pub v_begin: Vec<D::Twist>,
    pub order: Vec<u32>,
    pub prev_keys: Vec<PrevContact<D>>,
    pub next: Contacts<D>,
    /// The contacts by pair of materials, for the laws.
    pub laws: LawBatches,
    /// W_αα of the contacts being built.
    pub w: Vec<D::W>,
    /// The contacts' weights of [`World::contact_shares`].
    pub share: Vec<f64>,
    /// Detection restricted to this part of space (a rank's subdomains).
    pub region: Option<crate::detect::Region>,
    /// Last step's contacts held by other processes that this one may meet again
    /// (their warm starts), beside the world's own.
    pub extra_prev: Vec<PrevContact<D>>,
    /// The bodies this process steps (slots, ascending; `None`: all it holds): on
    /// MPI ranks, its own and its halo (`dd::owned`), which between steps are the
    /// bodies its world holds ([`held`]).
    pub active: Option<Vec<u32>>,
    /// `active` in global ids, for a world holding part of the scene.
    pub active_global: Option<Vec<u32>>,
}

impl<D: Dim> Default for Scratch<D> {
    fn default() -> Self {
        Scratch {
            detector: Detector::default(),
            raw: vec![],
            v_begin: vec![],
            order: vec![],
            prev_keys: vec![],
            next: Contacts::default(),
            laws: LawBatches::default(),
            w: vec![],
            share: vec![],
            region: None,
            extra_prev: vec![],
            active: None,
            active_global: None,
        }
    }
}

impl<D: Dim> World<D> {
    /// The bodies whose reactions are observed (ascending): those with a name or a
    /// drive (the history's tracked bodies, the box walls, servo-driven walls).
    pub fn observed(&self) -> Vec<u32> {
        (0..self.bodies.len() as u32)
            .filter(|&b| self.names[b as usize].is_some() || self.drives.iter().any(|d| d.body == b))
            .collect()
    }

    /// V⁻, the velocities at the start of the step being computed (kept by the
    /// free-velocity stage).
    pub fn velocity_begin(&self) -> &[D::Twist] {
        &self.scratch.v_begin
    }
    /// The contact law between two materials (`None`: they do not interact).
    pub fn law(&self, ma: u16, mb: u16) -> Option<&dyn Law> {
        self.laws[ma as usize * self.materials.len() + mb as usize].as_deref()
    }
    pub fn kind_name(&self, b: usize) -> &'static str {
        self.shapes[self.bodies.shape[b].kind as usize].kind()
    }
    /// A human name for body b (a slot): its user name, or its global id.
    pub fn body_label(&self, b: usize) -> String {
        let g = self.ids.global(b as u32);
        match &self.names[b] {
            Some(n) => format!("body {g} (`{n}`, {})", self.kind_name(b)),
            None => format!("body {g} ({})", self.kind_name(b)),
        }
    }
    /// Bounding box of body b at its pose.
    pub fn aabb(&self, b: usize) -> Aabb<D> {
        let s = self.bodies.shape[b];
        self.shapes[s.kind as usize].aabb(s.index, self.bodies.pos[b], self.bodies.rot[b])
    }
    /// Whether body b is a grain (a body of a grain shape, neither fixed nor driven).
    pub fn is_grain(&self, b: usize) -> bool {
        let s = self.bodies.shape[b];
        self.shapes[s.kind as usize].is_grain() && !self.fixed[b] && !self.drives.iter().any(|d| d.body as usize == b)
    }
    /// The inner box of the box sample, from its walls' bounding boxes.
    pub fn box_extent(&self) -> Option<Aabb<D>> {
        let w = self.box_walls.as_ref()?.walls;
        Some(Aabb {
            min: D::Point::from_fn(|k| self.aabb(w[2 * k] as usize).max[k]),
            max: D::Point::from_fn(|k| self.aabb(w[2 * k + 1] as usize).min[k]),
        })
    }
    /// Σ grain areas (3D: volumes) / box area (volume).
    pub fn solid_fraction(&self) -> Option<f64> {
        let e = self.box_extent()?;
        let v = self.grain_sums().1;
        Some(v / (0..D::N).map(|k| e.max[k] - e.min[k]).product::<f64>())
    }
    /// Mean stresses on the box walls (σ_xx, σ_yy[, σ_zz]), compression positive,
    /// from the last step's reactions (impulse / h over the wall's face).
    pub fn box_stresses(&self) -> Option<D::Point> {
        let e = self.box_extent()?;
        let w = self.box_walls.as_ref()?.walls;
        let h = self.time.h;
        let f = |b: u32, k: usize| self.reaction.get(b as usize).map_or(0.0, |r| r[k]) / h;
        Some(D::Point::from_fn(|k| 0.5 * (f(w[2 * k + 1], k) - f(w[2 * k], k)) / e.face(k)))
    }
    /// Number of contacts carrying a normal impulse, per body.
    pub fn loaded_contacts(&self) -> Vec<u32> {
        let mut count = vec![0u32; self.bodies.len()];
        let c = &self.contacts;
        for a in 0..c.len() {
            if c.r[a][0] > 0.0 {
                for b in c.bodies[a] {
                    count[b as usize] += 1;
                }
            }
        }
        count
    }
    /// Coordination numbers over the grains: `z` = 2 N_c / N_g with N_c the
    /// grain–grain contacts carrying a normal impulse, and `z_m`, the same without
    /// the rattlers (grains with fewer than 2 loaded contacts, walls included),
    /// counting grain–grain contacts between non-rattlers and the non-rattlers'
    /// wall contacts once.
    pub fn coordination(&self) -> (f64, f64) {
        let n = self.bodies.len();
        let grain: Vec<bool> = (0..n).map(|b| self.is_grain(b)).collect();
        let count = self.loaded_contacts();
        let c = &self.contacts;
        let ng = grain.iter().filter(|&&g| g).count();
        let ngg = (0..c.len())
            .filter(|&a| c.r[a][0] > 0.0 && c.bodies[a].iter().all(|&b| grain[b as usize]))
            .count();
        let (mut sum_m, mut n_m) = (0usize, 0usize);
        for b in 0..n {
            if grain[b] && count[b] >= 2 {
                n_m += 1;
                sum_m += count[b] as usize;
            }
        }
        let z = if ng > 0 { 2.0 * ngg as f64 / ng as f64 } else { 0.0 };
        let z_m = if n_m > 0 { sum_m as f64 / n_m as f64 } else { 0.0 };
        (z, z_m)
    }
    /// The largest grain size (radius of a disk or sphere).
    pub fn max_grain_size(&self) -> f64 {
        self.grain_sums().2
    }
    /// Kinetic energy and gravity potential of the bodies impulses can move.
    pub fn energies(&self) -> (f64, f64) {
        let (mut ek, mut ep) = (0.0, 0.0);
        for k in 0..self.bodies.len() {
            if let Some((e, p)) = self.body_energies(k) {
                ek += e;
                ep -= p;
            }
        }
        (ek, ep)
    }
    /// Body k's kinetic energy and m g·x (its potential is −m g·x), if impulses can
    /// move it: the terms of [`World::energies`].
    #[inline]
    pub fn body_energies(&self, k: usize) -> Option<(f64, f64)> {
        let b = &self.bodies;
        b.movable(k).then(|| {
            (
                D::kinetic_energy(b.mass[k], &b.inertia[k], &b.rot[k], &b.vel[k]),
                b.mass[k] * self.gravity.dot(&b.pos[k]),
            )
        })
    }
}

/// A contact of the last step, as the next step's warm start and bonds read it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PrevContact<D: Dim> {
    pub key: ContactKey,
    pub r: D::Local,
    pub bonded: bool,
    pub point: D::Point,
}
