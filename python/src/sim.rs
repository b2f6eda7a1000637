//! One loaded scene and its run, generic over the dimension: what the Python
//! class `Simulation` holds (lib.rs dispatches on the dimension).

use nscdd::dim::{Coords, Dim};
use nscdd::registry::Registry;
use nscdd::run::RunError;
use nscdd::run::Runner;
use nscdd::scene::Scene;
use std::io::Write;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// The history rows of a run, kept in memory (beside history.csv when the run has
/// an output folder).
#[derive(Clone, Default)]
pub struct Shared(pub Arc<Mutex<Vec<u8>>>);

impl Write for Shared {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0
            .lock()
            .map_err(|_| std::io::Error::other("the history buffer's lock"))?
            .extend_from_slice(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// A scene, its run (started with the simulation: its outputs' first frame), and
/// its history.
pub struct Sim<D: Dim> {
    pub scene: Scene<D>,
    pub run: Runner<D>,
    pub history: Shared,
    /// Steps made by this simulation (not counting a restart's).
    pub stepped: u64,
    /// A diverged run's message: no step or finish after it.
    pub failed: Option<String>,
}

impl<D: Dim> Sim<D> {
    /// Starts the run of `scene` (its solver: a setting it cannot use is an error
    /// here), writing in `out` when given.
    pub fn start(mut scene: Scene<D>, reg: &Registry, out: Option<PathBuf>) -> Result<Self, RunError> {
        let history = Shared::default();
        let run = Runner::start(&mut scene, reg, out.as_deref(), None, Some(Box::new(history.clone())))?;
        Ok(Sim {
            scene,
            run,
            history,
            stepped: 0,
            failed: None,
        })
    }

    /// Why the run cannot step: finished or diverged.
    fn closed(&self) -> Result<(), RunError> {
        if let Some(m) = &self.failed {
            return Err(RunError::Io(format!("the run stopped: {m}")));
        }
        if self.run.finished() {
            return Err(RunError::Io(
                "the run is finished (finish() wrote final.json): load the scene again, or restart from final.json".into(),
            ));
        }
        Ok(())
    }

    /// `n` steps (the scene's end moved past them if it comes first).
    pub fn steps(&mut self, n: u64) -> Result<Option<nscdd::engine::StepReport>, RunError> {
        self.closed()?;
        let target = self.scene.world.step + n;
        if target > self.scene.world.time.steps {
            self.scene.world.time.steps = target;
        }
        let mut last = None;
        for _ in 0..n {
            match self.run.step(&mut self.scene) {
                Ok(r) => last = Some(r),
                Err(e) => {
                    self.failed = Some(e.to_string());
                    return Err(e);
                }
            }
            self.stepped += 1;
        }
        Ok(last)
    }

    /// The end of the run: the series and final.json (with an output folder); its
    /// summary (again, once finished).
    pub fn finish(&mut self) -> Result<nscdd::run::RunSummary, RunError> {
        if self.run.finished() {
            return Ok(self.run.summary());
        }
        self.closed()?;
        self.run.finish(&mut self.scene)
    }

    /// Stopped by the user: checkpoint.json and the series written.
    pub fn interrupt(&mut self) -> Option<RunError> {
        match self.run.interrupt(&mut self.scene) {
            RunError::Interrupted(_) => None,
            e => Some(e),
        }
    }

    /// The state as a restart file at `path`.
    pub fn save(&mut self, path: &std::path::Path) -> Result<(), RunError> {
        self.run.save(&mut self.scene, path)
    }

    /// Flushes the history and returns its text.
    pub fn history_text(&mut self) -> String {
        let _ = self.run.flush();
        let buf = self.history.0.lock().map(|b| b.clone()).unwrap_or_default();
        String::from_utf8_lossy(&buf).into_owned()
    }

    /// Per body, the `width` values `f` gives.
    pub fn per_body(&self, width: usize, f: impl Fn(&nscdd::world::World<D>, usize, &mut Vec<f64>)) -> (Vec<f64>, usize) {
        let w = &self.scene.world;
        let n = w.bodies.len();
        let mut out = Vec::with_capacity(n * width);
        for k in 0..n {
            f(w, k, &mut out);
        }
        (out, width)
    }

    /// Where a view of the positions (`twist`: of the velocities, translation then
    /// rotation) starts: (pointer, bodies, values per body). The arrays are
    /// `[f64; k]` per body, contiguous; they are made at load and never grow (bodies
    /// are neither added nor removed while a simulation lives), so the pointer stays
    /// valid as long as the simulation.
    pub fn raw(&self, twist: bool) -> (*const f64, usize, usize) {
        let b = &self.scene.world.bodies;
        let n = b.pos.len();
        let per = |size: usize| size / std::mem::size_of::<f64>();
        match twist {
            false => (b.pos.as_ptr().cast(), n, per(std::mem::size_of::<D::Point>())),
            true => (b.vel.as_ptr().cast(), n, per(std::mem::size_of::<D::Twist>())),
        }
    }
    /// 2D: the angle (rad); 3D: the rotation vector (axis × angle).
    pub fn rotations(&self) -> (Vec<f64>, usize) {
        self.per_body(if D::N == 2 { 1 } else { 3 }, |w, k, o| {
            o.extend_from_slice(D::rot_to_vec(&w.bodies.rot[k]).coords())
        })
    }
    /// The radius of a ball, else the shape's size (as the VTK `radius` array).
    pub fn radii(&self) -> (Vec<f64>, usize) {
        self.per_body(1, |w, k, o| {
            let s = w.bodies.shape[k];
            let store = &w.shapes[s.kind as usize];
            o.push(match store.glyph(s.index, w.bodies.pos[k], w.bodies.rot[k]) {
                nscdd::shape::Glyph::Ball(r) => r,
                _ => store.size(s.index),
            });
        })
    }
    /// The shape kinds' names, and each body's kind (an index in them) and
    /// shape id within its kind.
    pub fn shapes(&self) -> (Vec<&'static str>, Vec<u16>, Vec<u32>) {
        let w = &self.scene.world;
        let names = w.shapes.iter().map(|s| s.kind()).collect();
        (
            names,
            w.bodies.shape.iter().map(|s| s.kind).collect(),
            w.bodies.shape.iter().map(|s| s.index).collect(),
        )
    }
    pub fn masses(&self) -> (Vec<f64>, usize) {
        self.per_body(1, |w, k, o| o.push(w.bodies.mass[k]))
    }

    /// The contacts' records ([`nscdd::output::contact_records`]).
    pub fn contacts(&self) -> (Vec<f64>, usize) {
        let w = &self.scene.world;
        let mut out = vec![];
        nscdd::output::contact_records(w, 0..w.contacts.len(), &mut out);
        (out, 3 + 4 * D::N + 2)
    }

    /// The last step's subdomains: (each body's (−1: no contacts), its number of
    /// copies, each contact's); None without NSCDD or before this simulation's
    /// first step.
    pub fn subdomains(&self) -> Option<(Vec<i32>, Vec<u32>, Vec<u32>)> {
        if self.stepped == 0 {
            return None;
        }
        let v = self.run.view(&self.scene)?;
        Some((v.body_subdomain, v.multiplicity, v.contact_subdomain))
    }

    /// The body named `name`, or of index `name`.
    pub fn body(&self, name: &str) -> Option<usize> {
        let w = &self.scene.world;
        w.names
            .iter()
            .position(|n| n.as_deref() == Some(name))
            .or_else(|| name.parse::<usize>().ok().filter(|&k| k < w.bodies.len()))
    }

    /// Sets the gravity of the rigid bodies (read at every step's free velocity);
    /// refused with body families, whose loads are assembled once.
    pub fn set_gravity(&mut self, g: &[f64]) -> Result<(), String> {
        if g.len() != D::N || !g.iter().all(|x| x.is_finite()) {
            return Err(format!("gravity takes {} finite numbers, got {g:?}", D::N));
        }
        if !self.scene.families.is_empty() {
            return Err(
                "gravity cannot change in a scene with deformable bodies or continuum regions (their loads are assembled once)".into(),
            );
        }
        self.scene.world.gravity.as_mut().copy_from_slice(g);
        Ok(())
    }

    /// Replaces the drive of degree of freedom `dof` of a driven body.
    pub fn set_drive(&mut self, body: usize, dof: &str, drive: nscdd::drive::DofDrive) -> Result<(), String> {
        let names: &[&str] = if D::N == 2 {
            &["x", "y", "rot"]
        } else {
            &["x", "y", "z", "rx", "ry", "rz"]
        };
        let slot = names
            .iter()
            .position(|&n| n == dof)
            .ok_or_else(|| format!("unknown degree of freedom `{dof}`: one of {}", names.join(", ")))?;
        let w = &mut self.scene.world;
        let d = w.drives.iter_mut().find(|d| d.body as usize == body).ok_or_else(|| {
            format!("body {body} has no drive in the scene: only a driven body's drives change between steps (give it one in the scene)")
        })?;
        d.dof[slot] = Some(drive);
        Ok(())
    }
}
