//! Running a loaded 3D scene to its end and writing its outputs in a directory
//! ([`crate::output::out3`]): the 3D counterpart of [`crate::run::run`].

use crate::dd::Nscdd3;
use crate::engine::StepReport;
use crate::output::out3::{final_json3, write_vtk3, History3};
use crate::output::vtk::VtkWriter;
use crate::run::{dd_solver, history_sink, io, save_state_text, write_rank_totals, RunError, RunSummary};
use crate::scene::load3::Scene3;
use crate::world::World3;
use std::path::Path;
use std::time::Instant;

fn save_state(dir: &Path, name: &str, w: &World3) -> Result<(), RunError> {
    save_state_text(dir, name, &final_json3(w))
}

/// Runs a 3D scene for its number of steps, writing `history.csv`, VTK frames every
/// `output.every` steps (and at the first and last step), `checkpoint.json` every
/// `output.checkpoint_every` steps and `final.json` in `dir`. With
/// `scene.decomposition`, every step is an NSCDD step ([`crate::dd::Nscdd3`]).
pub fn run3(scene: &mut Scene3, dir: &Path, on_step: impl FnMut(&World3, &StepReport)) -> Result<RunSummary, RunError> {
    run3_on(scene, dir, None, on_step)
}

/// [`run3`], as one rank of a multi-process run when `cluster` is given (see
/// [`crate::run::run_on`]).
pub fn run3_on(
    scene: &mut Scene3,
    dir: &Path,
    cluster: Option<Box<dyn crate::dd::Cluster>>,
    mut on_step: impl FnMut(&World3, &StepReport),
) -> Result<RunSummary, RunError> {
    let start = Instant::now();
    let root = cluster.as_ref().is_none_or(|c| c.rank() == 0);
    // a decomposed run steps with NSCDD (the same multiplier stage as in 2D)
    let mut dd: Option<Nscdd3> = dd_solver(scene.decomposition.as_ref(), cluster)?;
    let w = &mut scene.world;
    let mut hist = History3::with_columns(history_sink(dir, root)?, w, dd.is_some()).map_err(io(dir, "history.csv"))?;
    let mut vtk = (scene.output.vtk && root).then(VtkWriter::default);
    let mut frame = 0u32;
    if let Some(v) = vtk.as_mut() {
        write_vtk3(v, w, dir, frame).map_err(io(dir, "the first output frame"))?;
        frame += 1;
    }
    let mut sum = RunSummary::default();
    let steps = w.time.steps;
    for s in (w.step + 1)..=steps {
        let stepped = match &mut dd {
            Some(n) => n.step(w).map(|r| {
                sum.migrations += r.migrations as u64;
                let plain = StepReport {
                    solve: r.solve,
                    contacts: r.contacts,
                    times: r.times,
                };
                (plain, Some(r))
            }),
            None => w.step().map(|r| (r, None)),
        };
        let (rep, dd_rep) = match stepped {
            Ok(r) => r,
            Err(d) => {
                let _ = hist.flush();
                return Err(RunError::Diverged(d));
            }
        };
        let t0 = Instant::now();
        if (scene.output.every > 0 && s % scene.output.every == 0) || s == steps {
            if let Some(v) = vtk.as_mut() {
                write_vtk3(v, w, dir, frame).map_err(io(dir, "an output frame"))?;
                frame += 1;
            }
            hist.flush().map_err(io(dir, "history.csv"))?;
        }
        let t_out = t0.elapsed().as_secs_f64();
        hist.row_dd(w, &rep, dd_rep.as_ref(), t_out).map_err(io(dir, "history.csv"))?;
        if root && scene.output.checkpoint_every > 0 && s % scene.output.checkpoint_every == 0 && s != steps {
            hist.flush().map_err(io(dir, "history.csv"))?;
            save_state(dir, "checkpoint.json", w)?;
        }
        sum.record(&rep.solve, w.step, w.solver.tolerance);
        on_step(w, &rep);
    }
    hist.flush().map_err(io(dir, "history.csv"))?;
    write_rank_totals(&mut dd, dir)?;
    if root {
        save_state(dir, "final.json", w)?;
    }
    sum.wall_seconds = start.elapsed().as_secs_f64();
    Ok(sum)
}
