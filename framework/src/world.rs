//! A loaded 2D scene and its state: bodies, shapes, materials, laws, drives and the
//! contact set. Built by [`crate::scene`], advanced by [`crate::engine`].

use crate::detect::{Detector, DetectorTable};
use crate::drive::DofDrive;
use crate::law::ContactLaw;
use crate::registry::{RawContact2, ShapeStore2};
use crate::rigid2d::{Bodies2, Contacts2};
use crate::solver::SolverSettings;

/// A material: its name and density (kg/m³; per unit depth in 2D).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Material {
    pub name: String,
    pub density: f64,
}

/// The drives of one body, per degree of freedom (x, y, rot).
#[derive(Clone, Debug, PartialEq)]
pub struct BodyDrive2 {
    pub body: u32,
    pub dof: [Option<DofDrive>; 3],
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

/// The four walls bounding a box sample, for the solid fraction and the biaxial
/// stresses of the history.
#[derive(Clone, Debug, PartialEq)]
pub struct BoxWalls {
    pub left: u32,
    pub right: u32,
    pub bottom: u32,
    pub top: u32,
    /// ε1 is measured from the box height at this time.
    pub strain_from: f64,
}

/// The scene in memory.
pub struct World2 {
    pub bodies: Bodies2,
    /// Optional user names of bodies (for outputs), by body id.
    pub names: Vec<Option<String>>,
    /// One store per shape kind used by the scene; `bodies.shape[b].kind` indexes it.
    pub shapes: Vec<Box<dyn ShapeStore2>>,
    pub materials: Vec<Material>,
    /// Law of each material pair, `laws[ma * nm + mb]`.
    pub laws: Vec<Option<ContactLaw>>,
    pub drives: Vec<BodyDrive2>,
    pub gravity: [f64; 2],
    pub time: TimeSettings,
    pub solver: SolverSettings,
    /// Alert distance of the detection.
    pub alert: f64,
    pub box_walls: Option<BoxWalls>,
    /// Box height when ε1 starts (set by the engine).
    pub box_h0: Option<f64>,
    pub detectors: DetectorTable,
    /// Current time and completed steps.
    pub t: f64,
    pub step: u64,
    /// The last step's contacts (impulses kept for the warm start).
    pub contacts: Contacts2,
    /// Contact impulses resultant per body over the last step, Σ ±H r (N·s).
    pub reaction: Vec<[f64; 3]>,
    pub(crate) scratch: Scratch,
}

/// Buffers reused from step to step.
#[derive(Default)]
pub(crate) struct Scratch {
    pub detector: Detector,
    pub raw: Vec<RawContact2>,
    pub v_begin: Vec<[f64; 3]>,
    pub order: Vec<u32>,
    pub prev_keys: Vec<(crate::rigid2d::contacts::ContactKey, [f64; 2])>,
    pub next: Contacts2,
}

impl World2 {
    /// V⁻, the velocities at the start of the step being computed (kept by the
    /// free-velocity stage).
    pub fn velocity_begin(&self) -> &[[f64; 3]] {
        &self.scratch.v_begin
    }
    pub fn law(&self, ma: u16, mb: u16) -> Option<ContactLaw> {
        self.laws[ma as usize * self.materials.len() + mb as usize]
    }
    pub fn kind_name(&self, b: usize) -> &'static str {
        self.shapes[self.bodies.shape[b].kind as usize].kind()
    }
    /// A human name for body b: its user name, or its id.
    pub fn body_label(&self, b: usize) -> String {
        match &self.names[b] {
            Some(n) => format!("body {b} (`{n}`, {})", self.kind_name(b)),
            None => format!("body {b} ({})", self.kind_name(b)),
        }
    }
    /// Inner box of the box sample [x0, x1] × [y0, y1] from its walls' bounding boxes.
    pub fn box_extent(&self) -> Option<[f64; 4]> {
        let bw = self.box_walls.as_ref()?;
        let bb = |b: u32| {
            let s = self.bodies.shape[b as usize];
            self.shapes[s.kind as usize].aabb(s.index, self.bodies.pos[b as usize], self.bodies.rot[b as usize])
        };
        Some([bb(bw.left).max[0], bb(bw.right).min[0], bb(bw.bottom).max[1], bb(bw.top).min[1]])
    }
    /// Σ area of the grains (movable bodies of grain shapes) / box area.
    pub fn solid_fraction(&self) -> Option<f64> {
        let [x0, x1, y0, y1] = self.box_extent()?;
        let mut a = 0.0;
        for b in 0..self.bodies.len() {
            let s = self.bodies.shape[b];
            if self.shapes[s.kind as usize].is_grain() && self.bodies.movable(b) {
                a += self.bodies.volume[b];
            }
        }
        Some(a / ((x1 - x0) * (y1 - y0)))
    }
    /// Energies (kinetic, gravity potential) of the bodies impulses can move.
    pub fn energies(&self) -> (f64, f64) {
        let (mut ek, mut ep) = (0.0, 0.0);
        let b = &self.bodies;
        for k in 0..b.len() {
            if !b.movable(k) {
                continue;
            }
            let (v, m, i, x) = (b.vel[k], b.mass[k], b.inertia[k], b.pos[k]);
            ek += 0.5 * (m * v[0] * v[0] + m * v[1] * v[1] + i * v[2] * v[2]);
            ep -= m * (self.gravity[0] * x[0] + self.gravity[1] * x[1]);
        }
        (ek, ep)
    }
}
