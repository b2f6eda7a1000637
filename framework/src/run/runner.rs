//! A run stepped by its caller: the state of [`crate::run::run_on`] between two
//! steps (the NSCDD solver, the writers, history.csv, the frame counter), so that a
//! program (the Python module, a coupling script) can step a scene one step at a
//! time, read or change it between steps, and get the same outputs and the same
//! bits as `nscdd run`.
//!
//! ```no_run
//! use nscdd::run::Runner;
//! let reg = nscdd::registry::Registry::new();
//! let mut scene = nscdd::scene::load("deposit.toml".as_ref(), &reg).unwrap();
//! let out = std::path::Path::new("out");
//! let mut run = Runner::start(&mut scene, &reg, Some(out), None, None).unwrap();
//! while scene.world.step < scene.world.time.steps {
//!     let report = run.step(&mut scene).unwrap();
//!     println!("step {}: {} sweeps", scene.world.step, report.solve.sweeps);
//! }
//! let summary = run.finish(&mut scene).unwrap();
//! println!("{} sweeps in all", summary.total_sweeps);
//! ```

use crate::dd::{NscddOf, Rigid};
use crate::dim::Dim;
use crate::engine::StepReport;
use crate::output::history::History;
use crate::registry::{Registry, Writer};
use crate::run::{io, RunError, RunSummary};
use crate::scene::Scene;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// History rows written to two sinks.
struct Tee(Box<dyn Write + Send>, Box<dyn Write + Send>);

impl Write for Tee {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.write_all(buf)?;
        self.1.write_all(buf)?;
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush()?;
        self.1.flush()
    }
}

/// A run between two steps (module docs). Outputs go to `dir` when given (as
/// `nscdd run` writes them: history.csv, frames, checkpoints, final.json); without
/// one nothing is written but the history rows to the caller's copy.
pub struct Runner<D: Dim> {
    dd: Option<NscddOf<Rigid<D>>>,
    writers: Vec<Box<dyn Writer<D>>>,
    hist: History<Box<dyn Write + Send>, D>,
    columns: usize,
    values: Vec<f64>,
    frame: u32,
    /// The step of the last frame written.
    frame_step: Option<u64>,
    /// `finish` done: the series and final.json written.
    finished: bool,
    vtk: bool,
    dir: Option<PathBuf>,
    sum: RunSummary,
    start: Instant,
}

impl<D: Dim> Runner<D> {
    /// Starts a run of `scene` (its solver, writers and history; the first frame
    /// written), as one rank of `cluster` when given. The history rows go to
    /// `dir`/history.csv (nowhere without `dir`) and, when given, to `copy` too.
    pub fn start(
        scene: &mut Scene<D>,
        registry: &Registry,
        dir: Option<&Path>,
        cluster: Option<Box<dyn crate::dd::Cluster>>,
        copy: Option<Box<dyn Write + Send>>,
    ) -> Result<Self, RunError> {
        let start = Instant::now();
        let root = cluster.as_ref().is_none_or(|c| c.rank() == 0);
        let dd = crate::run::scene_solver(scene, cluster)?;
        let writers = match dir {
            Some(_) => crate::run::writers(scene, registry, root),
            None => vec![],
        };
        let w = &scene.world;
        let columns: Vec<String> = scene.families.iter().flat_map(|f| f.history_columns()).collect();
        let file: Box<dyn Write + Send> = match dir {
            Some(d) => crate::run::history_sink(d, root)?,
            None => Box::new(std::io::sink()),
        };
        let sink: Box<dyn Write + Send> = match copy {
            Some(c) => Box::new(Tee(file, c)),
            None => file,
        };
        let here = dir.unwrap_or(Path::new("."));
        let hist = History::with_columns(sink, w, dd.is_some(), &columns).map_err(io(here, "history.csv"))?;
        let mut r = Runner {
            dd,
            writers,
            hist,
            columns: columns.len(),
            values: vec![],
            frame: 0,
            frame_step: None,
            finished: false,
            vtk: scene.output.vtk && root && dir.is_some(),
            dir: dir.map(Path::to_path_buf),
            sum: RunSummary::default(),
            start,
        };
        if let Some(n) = r.dd.as_mut() {
            let touched = crate::family::touched(&scene.world, &scene.families);
            n.start_ranks(&mut scene.world, touched);
        }
        r.write_frame(scene).map_err(io(here, "the first output frame"))?;
        Ok(r)
    }

    fn here(&self) -> &Path {
        self.dir.as_deref().unwrap_or(Path::new("."))
    }

    fn write_frame(&mut self, scene: &mut Scene<D>) -> std::io::Result<()> {
        let Some(dir) = self.dir.as_deref() else { return Ok(()) };
        let w = &scene.world;
        let view = self.dd.as_ref().map(|n| n.view(w));
        for wr in self.writers.iter_mut() {
            match &view {
                Some(v) => wr.write_dd(w, v, dir, self.frame)?,
                None => wr.write(w, dir, self.frame)?,
            }
        }
        if scene.output.vtk {
            crate::run::gather_families(&mut self.dd, &mut scene.families, true);
            // (rank 0, and every rank for a family whose ranks write their own files)
            let ranks = self.dd.as_mut().and_then(|n| n.ranks_mut()).is_some();
            for f in scene.families.iter_mut().filter(|f| self.vtk || (ranks && f.frames_per_rank())) {
                if !self.vtk {
                    // (the folder rank 0 makes, maybe not yet)
                    std::fs::create_dir_all(dir)?;
                }
                f.write_frame(dir, self.frame, w.t)?;
            }
        }
        self.frame += 1;
        self.frame_step = Some(scene.world.step);
        Ok(())
    }

    /// Whether a frame follows step `s` (every `output.every` steps and the last).
    fn frame_after(scene: &Scene<D>, s: u64) -> bool {
        (scene.output.every > 0 && s % scene.output.every == 0) || s == scene.world.time.steps
    }

    /// One step of the scene, with its frame, history row and checkpoint when due.
    /// A diverging body stops it ([`RunError::Diverged`], the history flushed).
    pub fn step(&mut self, scene: &mut Scene<D>) -> Result<StepReport, RunError> {
        let s = scene.world.step + 1;
        if let Some(n) = self.dd.as_mut() {
            n.skip_view(!Self::frame_after(scene, s));
        }
        let mut refs: Vec<&mut dyn crate::family::SceneFamily<D>> = scene.families.iter_mut().map(|f| &mut **f).collect();
        let (rep, dd_rep) = match crate::family::step(&mut scene.world, &mut refs, self.dd.as_mut()) {
            Ok(r) => r,
            Err(d) => {
                let _ = self.hist.flush();
                return Err(RunError::Diverged(d));
            }
        };
        let t0 = Instant::now();
        if Self::frame_after(scene, s) {
            self.write_frame(scene).map_err(io(self.here(), "an output frame"))?;
            self.hist.flush().map_err(io(self.here(), "history.csv"))?;
        }
        let t_out = t0.elapsed().as_secs_f64();
        self.values.clear();
        scene.families.iter().for_each(|f| f.history_values(&mut self.values));
        debug_assert_eq!(
            self.values.len(),
            self.columns,
            "the families' history values and columns differ in number"
        );
        let w = &scene.world;
        self.hist
            .row_dd(w, &rep, dd_rep.as_ref(), t_out, &self.values)
            .map_err(io(self.here(), "history.csv"))?;
        let every = scene.output.checkpoint_every;
        if every > 0 && s % every == 0 && s != w.time.steps {
            self.checkpoint(scene, "checkpoint.json")?;
        }
        if let Some(r) = &dd_rep {
            self.sum.migrations += r.migrations as u64;
        }
        self.sum.record(&rep.solve, scene.world.step, scene.world.solver.tolerance);
        Ok(rep)
    }

    /// Writes the state as `name` in the output directory (nothing without one):
    /// a restart file (collective on MPI ranks).
    pub fn checkpoint(&mut self, scene: &mut Scene<D>, name: &str) -> Result<(), RunError> {
        let Some(dir) = self.dir.clone() else { return Ok(()) };
        self.hist.flush().map_err(io(&dir, "history.csv"))?;
        crate::run::save_state(&dir, name, &mut scene.world, &mut scene.families, &mut self.dd)
    }

    /// Writes the state as a restart file at `path` (any name; its folder made if
    /// missing).
    pub fn save(&mut self, scene: &mut Scene<D>, path: &Path) -> Result<(), RunError> {
        let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .ok_or_else(|| RunError::Io(format!("{}: not a file name (UTF-8)", path.display())))?;
        std::fs::create_dir_all(dir).map_err(io(dir, name))?;
        crate::run::save_state(dir, name, &mut scene.world, &mut scene.families, &mut self.dd)
    }

    /// Whether a stop was asked ([`crate::run::request_stop`]) on this process or,
    /// on several ranks, on any of them (collective: every rank calls it).
    pub fn stop_agreed(&mut self) -> bool {
        crate::run::stop_agreed(&mut self.dd)
    }

    /// The end of a run stopped before its last step: `checkpoint.json` and the
    /// series written, [`RunError::Interrupted`] returned for step `s`.
    pub fn interrupt(&mut self, scene: &mut Scene<D>) -> RunError {
        let s = scene.world.step;
        let done = self.checkpoint(scene, "checkpoint.json").and_then(|()| self.finish_outputs(scene));
        match done {
            Ok(()) => RunError::Interrupted(s),
            Err(e) => e,
        }
    }

    fn finish_outputs(&mut self, scene: &mut Scene<D>) -> Result<(), RunError> {
        let Some(dir) = self.dir.clone() else { return Ok(()) };
        crate::run::finish_outputs(&mut self.writers, &mut scene.families, self.vtk, &dir)
    }

    /// With NSCDD (a decomposition, or body families): the last step's subdomains
    /// of the contacts and the bodies ([`crate::dd::DdView`]); None without.
    pub fn view(&self, scene: &Scene<D>) -> Option<crate::dd::DdView> {
        self.dd.as_ref().map(|n| n.view(&scene.world))
    }

    /// The run's totals so far (`wall_seconds` since the start).
    pub fn summary(&self) -> RunSummary {
        let mut s = self.sum.clone();
        s.wall_seconds = self.start.elapsed().as_secs_f64();
        s
    }

    /// The history flushed to its sink.
    pub fn flush(&mut self) -> Result<(), RunError> {
        self.hist.flush().map_err(io(self.here(), "history.csv"))
    }

    /// Whether [`Runner::finish`] was called.
    pub fn finished(&self) -> bool {
        self.finished
    }

    /// The end of the run: history flushed, a last frame if the current step has
    /// none (a caller that stops before the scene's last step), the series (`.pvd`)
    /// and `final.json` written (and on ranks `ranks.json`); its summary. The run
    /// keeps its state (`save`, `view`) but must not be stepped again.
    pub fn finish(&mut self, scene: &mut Scene<D>) -> Result<RunSummary, RunError> {
        self.flush()?;
        if self.frame_step != Some(scene.world.step) {
            self.write_frame(scene).map_err(io(self.here(), "the last output frame"))?;
        }
        self.finish_outputs(scene)?;
        if let Some(dir) = self.dir.clone() {
            crate::run::save_state(&dir, "final.json", &mut scene.world, &mut scene.families, &mut self.dd)?;
            // after final.json: the peak memory of each rank counts its writing
            crate::run::write_rank_totals(&mut self.dd, &dir)?;
        }
        self.finished = true;
        self.sum.wall_seconds = self.start.elapsed().as_secs_f64();
        Ok(self.sum.clone())
    }
}
