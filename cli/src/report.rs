//! What `nscdd run` shows and returns, for 2D and 3D runs alike: the progress bar,
//! the input error left in DIR, and the run's summary and exit code.

use indicatif::{ProgressBar, ProgressStyle};
use nscdd::engine::StepReport;
use nscdd::run::{RunError, RunSummary};
use std::path::Path;
use std::process::ExitCode;

/// A progress bar over `steps` steps starting at `start` (hidden with `quiet`).
pub fn progress(quiet: bool, steps: u64, start: u64) -> ProgressBar {
    let bar = if quiet { ProgressBar::hidden() } else { ProgressBar::new(steps) };
    bar.set_position(start);
    bar.set_style(
        ProgressStyle::with_template("{bar:30} step {pos}/{len} | {msg} | {elapsed_precise} elapsed, {eta_precise} left")
            .expect("valid template"),
    );
    bar
}

/// The bar after step `step` of `steps`.
pub fn on_step(bar: &ProgressBar, steps: u64, step: u64, rep: &StepReport) {
    bar.set_position(step);
    if step % 10 == 0 || step == steps {
        bar.set_message(format!(
            "{} contacts, {} sweeps{}",
            rep.contacts,
            rep.solve.sweeps,
            if rep.solve.converged { "" } else { " (not converged)" }
        ));
    }
}

/// Bad input to `run`: the message in DIR/error.txt (nothing else) and exit code 2.
pub fn input_error_in(out: &Path, e: impl std::fmt::Display) -> ExitCode {
    if std::fs::create_dir_all(out).is_ok() {
        let _ = std::fs::write(out.join("error.txt"), format!("{e}\n"));
    }
    crate::input_error(e)
}

/// The end of a run: warnings and summary (`dd`: the decomposition's description),
/// or the error that stopped it (exit code 1).
pub fn finish(res: Result<RunSummary, RunError>, norm: &str, dd: impl Fn(&RunSummary) -> String, out: &Path) -> ExitCode {
    match res {
        Ok(sum) => {
            // a refused earlier run in the same folder left its message: not this run's
            let _ = std::fs::remove_file(out.join("error.txt"));
            for line in sum.warnings(norm) {
                eprintln!("{line}");
            }
            eprintln!(
                "{} steps{}, {} sweeps, {:.2} s; outputs in {}",
                sum.steps,
                dd(&sum),
                sum.total_sweeps,
                sum.wall_seconds,
                out.display()
            );
            ExitCode::SUCCESS
        }
        Err(RunError::Interrupted(step)) => {
            let ck = out.join("checkpoint.json");
            eprintln!(
                "stopped on request at the end of step {step}; its state is in {} (continue with `--restart {}` and another --out)",
                ck.display(),
                ck.display()
            );
            ExitCode::from(130)
        }
        // bad input found when the run starts (ranks against the decomposition, a
        // setting the solver cannot use): nothing was run
        Err(e) if e.exit_code() == 2 => input_error_in(out, e),
        Err(e) => {
            eprintln!("error: {e}; the outputs written so far are kept in {}", out.display());
            ExitCode::from(1)
        }
    }
}

/// ", on P ranks" for a multi-process run.
pub fn on_ranks(size: u32) -> String {
    if size > 1 {
        format!(", on {size} ranks")
    } else {
        String::new()
    }
}

/// [`finish`] for one of `ranks`: rank 0 reports; a decomposition that does not fit
/// the ranks is bad input (exit 2 on every rank); an output that rank 0 cannot write
/// stops every rank ([`crate::ranks::Ranks::abort_others`]).
pub fn finish_on(
    ranks: &crate::ranks::Ranks,
    res: Result<RunSummary, RunError>,
    norm: &str,
    dd: impl Fn(&RunSummary) -> String,
    out: &Path,
) -> ExitCode {
    match &res {
        Err(RunError::Ranks(m)) => return if ranks.root() { input_error_in(out, m) } else { ExitCode::from(2) },
        Err(RunError::Io(m)) if ranks.size() > 1 => {
            return ranks.abort_others(1, &format!("{m}; the outputs written so far are kept in {}", out.display()))
        }
        _ => {}
    }
    if !ranks.root() {
        return if res.is_ok() { ExitCode::SUCCESS } else { ExitCode::from(1) };
    }
    finish(res, norm, dd, out)
}
