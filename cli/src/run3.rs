//! `nscdd run` on a 3D scene.

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
        return crate::report::input_error_in(out, msg);
    }
    let steps = s.world.time.steps;
    let bar = crate::report::progress(quiet, steps, s.world.step);
    let res = nscdd::run3::run3(&mut s, out, |w, rep| crate::report::on_step(&bar, steps, w.step, rep));
    bar.finish_and_clear();
    let dd = |sum: &nscdd::run::RunSummary| match &s.decomposition {
        Some(c) => format!(
            " ({}x{}x{} subdomains, {:?}, {} migrations)",
            c.dd.nx, c.dd.ny, c.dd.nz, c.dd.scheme, sum.migrations
        ),
        None => String::new(),
    };
    crate::report::finish(res, s.world.solver.norm.name(), dd, out)
}
