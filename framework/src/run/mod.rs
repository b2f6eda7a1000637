//! Running a loaded scene (2D or 3D) to its end and writing its outputs in a
//! directory.

pub mod runner;

pub use runner::Runner;

use crate::dd::{NscddOf, Rigid};
use crate::dim::Dim;
use crate::engine::StepReport;
use crate::family::SceneFamily;
use crate::registry::{Registry, Writer};
use crate::scene::Scene;
use crate::world::World;
use std::io::Write;
use std::path::Path;

/// Why a run stopped early: the library's [`crate::Error`] (`Io`, `Diverged`,
/// `Ranks`).
pub type RunError = crate::error::Error;

/// What a finished run did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunSummary {
    pub steps: u64,
    /// Steps whose contact solve did not meet the criterion.
    pub unconverged_steps: u64,
    pub first_unconverged: Option<u64>,
    pub total_sweeps: u64,
    pub wall_seconds: f64,
    /// Steps the criterion accepted although their natural-map residual exceeds
    /// [`SUSPECT_FACTOR`] × tolerance: LMGC90's norms measure the change over a sweep,
    /// so a stalled solve can pass them (see docs/EXTREMES.md).
    pub suspect_steps: u64,
    /// Largest natural-map residual of the run, and its step.
    pub max_residual: f64,
    pub max_residual_step: u64,
    /// Decomposed runs: migrations summed over the repartitions.
    pub migrations: u64,
}

/// A converged step whose residual exceeds this factor × the solver tolerance is
/// counted as suspect.
pub const SUSPECT_FACTOR: f64 = 100.0;

impl RunSummary {
    /// Counts one finished step (its solve report, its number, the tolerance).
    pub fn record(&mut self, solve: &crate::solver::SolveReport, step: u64, tolerance: f64) {
        self.steps += 1;
        self.total_sweeps += solve.sweeps as u64;
        if !solve.converged {
            self.unconverged_steps += 1;
            self.first_unconverged.get_or_insert(step);
        } else if solve.residual > SUSPECT_FACTOR * tolerance {
            self.suspect_steps += 1;
        }
        if solve.residual > self.max_residual {
            self.max_residual = solve.residual;
            self.max_residual_step = step;
        }
    }

    /// The warnings a finished run prints (unconverged and suspect steps), one per
    /// line; `norm` names the criterion.
    pub fn warnings(&self, norm: &str) -> Vec<String> {
        let mut out = vec![];
        if self.unconverged_steps > 0 {
            out.push(format!(
                "warning: the contact solver did not converge in {} of {} steps (first: step {}); see the `converged` column of history.csv",
                self.unconverged_steps,
                self.steps,
                self.first_unconverged.unwrap_or(0)
            ));
        }
        if self.suspect_steps > 0 {
            out.push(format!(
                "warning: {} steps met the {norm} criterion with a natural-map residual above {SUSPECT_FACTOR} × tolerance (largest {:.2e} at step {}): the solve stalled; lower solver.tolerance (docs/EXTREMES.md)",
                self.suspect_steps, self.max_residual, self.max_residual_step
            ));
        }
        out
    }
}

pub(crate) fn io(dir: &Path, what: &str) -> impl Fn(std::io::Error) -> RunError {
    let d = dir.display().to_string();
    let what = what.to_string();
    move |e| RunError::Io(format!("cannot write {what} in {d}: {e}"))
}

/// Writes a saved state (a restart file, `text`) as `name` in `dir`, through a
/// temporary file renamed into place, so that a run killed while writing keeps the
/// previous one.
pub(crate) fn save_state_text(dir: &Path, name: &str, text: &str) -> Result<(), RunError> {
    save_state_with(dir, name, |f| f.write_all(text.as_bytes()))
}

/// [`save_state_text`], the file's text written by `write` as it is made
/// ([`crate::output::write_atomic`]).
fn save_state_with(dir: &Path, name: &str, write: impl FnOnce(&mut std::fs::File) -> std::io::Result<()>) -> Result<(), RunError> {
    crate::output::write_atomic(&dir.join(name), |tmp| write(&mut std::fs::File::create(tmp)?)).map_err(io(dir, name))
}

/// The outputs of a run: written by one process only (rank 0 of a multi-process
/// run); the others step the same world and write nothing.
pub(crate) fn history_sink(dir: &Path, root: bool) -> Result<Box<dyn Write + Send>, RunError> {
    if !root {
        return Ok(Box::new(std::io::sink()));
    }
    std::fs::create_dir_all(dir).map_err(io(dir, "the output directory"))?;
    // unbuffered: each row is one write (whole lines after a kill)
    let file = std::fs::File::create(dir.join("history.csv")).map_err(io(dir, "history.csv"))?;
    Ok(Box::new(file))
}

static STOP: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Asks the running [`run_on`] to stop at the end of its current step, after
/// writing `checkpoint.json` (a signal handler's call: SIGINT, SIGTERM). It then
/// returns [`RunError::Interrupted`]. On several ranks, the ranks agree at the end of
/// every step ([`stop_agreed`]): a request on any rank stops all of them after the
/// same step.
pub fn request_stop() {
    STOP.store(true, std::sync::atomic::Ordering::SeqCst);
}

fn stop_requested() -> bool {
    STOP.load(std::sync::atomic::Ordering::SeqCst)
}

/// Whether the run stops after this step: a request on this process or, on several
/// ranks, on any of them (one collective reduction per step, every rank calls it).
pub(crate) fn stop_agreed<D: Dim>(dd: &mut Option<NscddOf<Rigid<D>>>) -> bool {
    let mine = stop_requested();
    match dd.as_mut().and_then(|n| n.ranks_mut()) {
        Some(rs) => rs.cluster.min_max(mine as u64).1 > 0,
        None => mine,
    }
}

/// The NSCDD solver of a decomposed scene, over the ranks of `cluster` when given.
pub(crate) fn dd_solver<D: crate::dd::Family>(
    c: Option<&crate::dd::DdConfig>,
    cluster: Option<Box<dyn crate::dd::Cluster>>,
) -> Result<Option<crate::dd::NscddOf<D>>, RunError> {
    let Some(c) = c else {
        return match cluster {
            Some(cl) if cl.size() > 1 => Err(RunError::Ranks(format!(
                "{} ranks but the scene has no decomposition: give --subdomains or a [decomposition] section",
                cl.size()
            ))),
            _ => Ok(None),
        };
    };
    let n = c.solver_of::<D>();
    match cluster {
        Some(cl) => {
            // MPI launchers bind each rank to one core by default: threads inside a
            // rank then share it (the run is right, but slower than one thread)
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            if c.dd.threads > cores {
                eprintln!(
                    "warning: rank {} may run on {cores} core(s) for {} threads (the launcher's binding: \
                     `mpirun --bind-to none` or `--map-by slot:PE={}` gives each rank its cores)",
                    cl.rank(),
                    c.dd.threads,
                    c.dd.threads
                );
            }
            // contacts held per rank: a repartition detects and builds twice
            if c.repartition_every <= 1 && cl.size() > 1 && cl.rank() == 0 {
                eprintln!(
                    "note: the subdomains are re-partitioned at every step ([decomposition] repartition_every = 1): \
                     on ranks a repartition detects and builds the contacts twice; every 10 steps or so is usually \
                     faster (docs/SCALING.md)"
                );
            }
            n.with_cluster(cl).map(Some).map_err(RunError::Ranks)
        }
        None => Ok(Some(n)),
    }
}

/// The end of a multi-process run (collective): every rank's exchange totals in
/// `ranks.json`, written by rank 0.
pub(crate) fn write_rank_totals<D: crate::dd::Family>(dd: &mut Option<crate::dd::NscddOf<D>>, dir: &Path) -> Result<(), RunError> {
    if let Some(rs) = dd.as_mut().and_then(|n| n.ranks_mut()) {
        let text = crate::dd::ranks::totals_json(rs);
        if rs.cluster.rank() == 0 {
            save_state_text(dir, "ranks.json", &text)?;
        }
    }
    Ok(())
}

/// On MPI ranks, before an output reads the families' state: what rank 0 lacks of
/// it, sent there ([`crate::dd::Attached::gather_whole`]; collective); before a
/// frame (`frame`), not of a family whose ranks write their own frame files
/// ([`crate::dd::Attached::frames_per_rank`]).
pub(crate) fn gather_families<D: Dim>(dd: &mut Option<NscddOf<Rigid<D>>>, families: &mut [Box<dyn SceneFamily<D>>], frame: bool) {
    let Some(rs) = dd.as_mut().and_then(|n| n.ranks_mut()) else {
        return;
    };
    let fams = families.iter_mut().filter(|f| !(frame && f.frames_per_rank()));
    crate::dd::with_rounds(rs, |r| fams.for_each(|f| f.gather_whole(r)));
}

/// Writes the state on rank 0. Collective on MPI ranks (F_Γ is gathered from every
/// rank, and the bodies, contacts and kept contacts other ranks hold are merged on
/// rank 0 as it writes them, [`crate::dd::rank_merge`]): every rank calls it at the
/// same step.
pub(crate) fn save_state<D: Dim>(
    dir: &Path,
    name: &str,
    w: &mut World<D>,
    families: &mut [Box<dyn SceneFamily<D>>],
    dd: &mut Option<NscddOf<Rigid<D>>>,
) -> Result<(), RunError> {
    gather_families(dd, families, false);
    let families = &*families;
    // bodies held per rank: every body's record from its owner; contacts held per
    // rank: every rank's, in key order
    let bodies = dd.as_mut().and_then(|n| n.own_body_records(w));
    let contacts = dd.as_ref().filter(|n| n.holds_own_contacts()).map(|_| {
        let order = crate::output::contacts_in_key_order(w);
        let mut mine = Vec::new();
        crate::output::contact_records(w, order.into_iter().map(|a| a as usize), &mut mine);
        mine
    });
    let states = || (!families.is_empty()).then(|| crate::family::states(families));
    let Some((state, kept)) = dd.as_mut().and_then(|n| n.state_on_ranks()) else {
        let (state, states) = (dd.as_ref().and_then(|n| n.save_state()), states());
        return save_state_with(dir, name, |f| {
            crate::output::write_final_json(f, w, states.as_ref(), state.as_ref(), (None, None))
        });
    };
    let Some(rs) = dd.as_mut().and_then(|n| n.ranks_mut()) else {
        return Err(RunError::Io(format!("internal error: {name}: a state of ranks without ranks")));
    };
    let (pull_bodies, pull_contacts) = (bodies.is_some(), contacts.is_some());
    let body_rec = 1 + World::<D>::OUTPUT_RECORD;
    let contact_rec = crate::output::contact_record_len(D::N);
    // in the order of the file: bodies, contacts, kept contacts
    let mut merges = rs.merges(vec![
        (bodies.unwrap_or_default(), body_rec, 1),
        (contacts.unwrap_or_default(), contact_rec, 3),
        (kept, 4, 3),
    ]);
    if rs.cluster.rank() != 0 {
        merges.serve(rs);
        return Ok(());
    }
    let states = states();
    let both = std::cell::RefCell::new((rs, merges));
    let pull = |i: usize, out: &mut Vec<f64>| {
        let (rs, m) = &mut *both.borrow_mut();
        m.pull(i, rs, out)
    };
    let (mut next_body, mut next_contact, mut next_kept) = (
        |o: &mut Vec<f64>| pull(0, o),
        |o: &mut Vec<f64>| pull(1, o),
        |o: &mut Vec<f64>| pull(2, o),
    );
    let pulls: (Option<crate::output::Pull>, Option<crate::output::Pull>) = (
        pull_contacts.then_some(&mut next_contact as crate::output::Pull),
        pull_bodies.then_some(&mut next_body as crate::output::Pull),
    );
    let state = state.as_ref().map(|s| s.with_kept(&mut next_kept));
    let written = save_state_with(dir, name, |f| {
        crate::output::write_final_json(f, w, states.as_ref(), state.as_ref(), pulls)
    });
    // every merge ended for every rank, the file written or not
    let (rs, mut merges) = both.into_inner();
    let whole = merges.finish(rs);
    match written {
        Ok(()) if !whole => Err(RunError::Io(format!("internal error: {name} misses records of other ranks"))),
        _ => written,
    }
}

/// Runs `scene` for its number of steps, writing `history.csv`, the writers' frames
/// (VTK with `output.vtk`) every `output.every` steps (and at the first and last
/// step), `checkpoint.json` every `output.checkpoint_every` steps and `final.json`
/// in `dir`. `on_step` is called after every step (progress display). With
/// `scene.decomposition` set, every step is an NSCDD step ([`NscddOf`]),
/// history.csv gains the NSCDD columns and the VTK frames the subdomain arrays.
pub fn run<D: Dim>(
    scene: &mut Scene<D>,
    registry: &Registry,
    dir: &Path,
    on_step: impl FnMut(&World<D>, &StepReport),
) -> Result<RunSummary, RunError> {
    run_on(scene, registry, dir, None, on_step)
}

/// The writers of a run: on rank 0 all of them, on the other MPI ranks the VTK
/// writer alone (each rank writes its piece of a frame).
pub(crate) fn writers<D: Dim>(scene: &Scene<D>, registry: &Registry, root: bool) -> Vec<Box<dyn Writer<D>>> {
    let mut out: Vec<Box<dyn Writer<D>>> = vec![];
    if !root {
        out.extend(scene.output.vtk.then(|| registry.writer::<D>("vtk")).flatten().map(|make| make()));
        return out;
    }
    let names = scene
        .output
        .vtk
        .then_some("vtk")
        .into_iter()
        .chain(scene.output.writers.iter().map(|s| s.as_str()));
    // the loader checked every name
    out.extend(names.filter_map(|n| registry.writer::<D>(n)).map(|make| make()));
    out
}

/// The end of the writers' and the families' series (`.pvd`).
pub(crate) fn finish_outputs<D: Dim>(
    writers: &mut [Box<dyn Writer<D>>],
    fams: &mut [Box<dyn SceneFamily<D>>],
    vtk: bool,
    dir: &Path,
) -> Result<(), RunError> {
    for wr in writers.iter_mut() {
        wr.finish(dir).map_err(io(dir, "the output series"))?;
    }
    if vtk {
        for f in fams.iter_mut() {
            f.finish(dir).map_err(io(dir, "the output series"))?;
        }
    }
    Ok(())
}

/// The NSCDD solver of a scene: its decomposition's, or one subdomain where its
/// body families need NSCDD without one; with a restart's saved state when it is
/// of the same decomposition.
pub(crate) fn scene_solver<D: Dim>(
    scene: &mut Scene<D>,
    cluster: Option<Box<dyn crate::dd::Cluster>>,
) -> Result<Option<NscddOf<Rigid<D>>>, RunError> {
    let one = crate::dd::DdConfig::default();
    let dd_config = scene
        .decomposition
        .as_ref()
        .or(crate::family::needs_nscdd(false, &mut scene.families).then_some(&one));
    let mut dd: Option<NscddOf<Rigid<D>>> = dd_solver(dd_config, cluster)?;
    if dd.is_some() && scene.world.solver.ordering == crate::solver::Ordering::Scrambled {
        return Err(RunError::Param(crate::error::ParamError::new(
            "solver.ordering",
            "`scrambled` re-permutes the contacts of the one-domain NLGS before every block of sweeps; \
             NSCDD's subdomains (a decomposition, or body families) sweep in one order a step: use `shuffled`",
        )));
    }
    let method = scene.world.solver.method;
    let families = !scene.families.is_empty();
    let refusal = match method {
        crate::solver::Method::Nlgs => None,
        _ if dd.is_none() => None,
        crate::solver::Method::Newton => Some(
            "`newton` solves the one-domain problem over the assembled W; NSCDD's subdomains (a decomposition, or body \
             families) are swept between gluing stages: use method = \"nlgs\" or \"anderson\"",
        ),
        crate::solver::Method::Anderson if families => Some(
            "`anderson` over NSCDD mixes rigid bodies' impulses only; the scene's body families (deformable bodies) \
             need method = \"nlgs\"",
        ),
        crate::solver::Method::Anderson => None,
    };
    if let Some(msg) = refusal {
        return Err(RunError::Param(crate::error::ParamError::new("solver.method", msg)));
    }
    // a fresh scene loaded in part: the first step starts from the loader's grid
    if let (Some(n), Some(part)) = (dd.as_mut(), scene.part.take()) {
        n.start_from(part);
    }
    // a restarted run of the same decomposition continues its F_Γ
    if let (Some(n), Some(state)) = (dd.as_mut(), scene.dd_state.take()) {
        n.load_state(state)
            .map_err(|m| RunError::Ranks(format!("the restart file's `nscdd` state: {m}")))?;
    }
    Ok(dd)
}

/// [`run`], as one rank of a multi-process run when `cluster` is given: every rank
/// steps its part of the world (or the whole world: body families that may touch
/// any body, by model on more ranks than cells) and sweeps its subdomains ([`crate::dd::ranks`]); rank 0
/// writes the outputs (the same files as one process, and `ranks.json`), except the
/// VTK frames, of which every rank writes its piece (`.pvtp` by rank 0). A scene's
/// body families ([`crate::family`]) step with the world, add their history columns
/// and VTK frames, and save their state in `final.json` and the checkpoints. The
/// steps are [`Runner`]'s.
pub fn run_on<D: Dim>(
    scene: &mut Scene<D>,
    registry: &Registry,
    dir: &Path,
    cluster: Option<Box<dyn crate::dd::Cluster>>,
    mut on_step: impl FnMut(&World<D>, &StepReport),
) -> Result<RunSummary, RunError> {
    let mut run = Runner::start(scene, registry, Some(dir), cluster, None)?;
    let steps = scene.world.time.steps;
    // a restarted world continues from its saved step
    for s in (scene.world.step + 1)..=steps {
        let rep = run.step(scene)?;
        on_step(&scene.world, &rep);
        if s != steps && run.stop_agreed() {
            return Err(run.interrupt(scene));
        }
    }
    run.finish(scene)
}
