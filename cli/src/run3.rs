//! `nscdd run` on a 3D scene.

use indicatif::{ProgressBar, ProgressStyle};
use std::path::Path;
use std::process::ExitCode;

/// Runs a loaded 3D scene with the command line's decomposition flags.
pub fn run(
    mut s: nscdd::scene::load3::Scene3,
    out: &Path,
    quiet: bool,
    subdomains: Option<&str>,
    scheme: Option<&str>,
    threads: Option<&str>,
    restart: Option<&Path>,
) -> ExitCode {
    let movable = (0..s.world.bodies.len()).filter(|&b| s.world.bodies.movable(b)).count();
    let flags =
        crate::apply_decomposition_to(&mut s.decomposition, movable, true, subdomains, scheme, threads).and_then(|()| match restart {
            Some(state) => {
                crate::check_restart_dir(out, state)?;
                nscdd::scene::restart3::restart3(&mut s.world, state).map_err(|e| e.to_string())
            }
            None => Ok(()),
        });
    if let Err(msg) = flags {
        if std::fs::create_dir_all(out).is_ok() {
            let _ = std::fs::write(out.join("error.txt"), format!("{msg}\n"));
        }
        eprintln!("error: {msg}");
        return ExitCode::from(2);
    }
    let steps = s.world.time.steps;
    let bar = if quiet { ProgressBar::hidden() } else { ProgressBar::new(steps) };
    bar.set_position(s.world.step);
    bar.set_style(
        ProgressStyle::with_template("{bar:30} step {pos}/{len} | {msg} | {elapsed_precise} elapsed, {eta_precise} left")
            .expect("valid template"),
    );
    let res = nscdd::run3::run3(&mut s, out, |w, rep| {
        bar.set_position(w.step);
        if w.step % 10 == 0 || w.step == steps {
            bar.set_message(format!(
                "{} contacts, {} sweeps{}",
                rep.contacts,
                rep.solve.sweeps,
                if rep.solve.converged { "" } else { " (not converged)" }
            ));
        }
    });
    bar.finish_and_clear();
    match res {
        Ok(sum) => {
            for line in sum.warnings(s.world.solver.norm.name()) {
                eprintln!("{line}");
            }
            let dd = match &s.decomposition {
                Some(c) => format!(
                    " ({}x{}x{} subdomains, {:?}, {} migrations)",
                    c.dd.nx, c.dd.ny, c.dd.nz, c.dd.scheme, sum.migrations
                ),
                None => String::new(),
            };
            eprintln!(
                "{} steps{dd}, {} sweeps, {:.2} s; outputs in {}",
                sum.steps,
                sum.total_sweeps,
                sum.wall_seconds,
                out.display()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}; the outputs written so far are kept in {}", out.display());
            ExitCode::from(1)
        }
    }
}
