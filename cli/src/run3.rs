//! `nscdd run` on a 3D scene.

use crate::ranks::Ranks;
use std::path::Path;
use std::process::ExitCode;

/// The command line's flags of a run.
pub struct Flags<'a> {
    pub subdomains: Option<&'a str>,
    pub scheme: Option<&'a str>,
    pub threads: Option<&'a str>,
    pub restart: Option<&'a Path>,
}

/// Runs a loaded 3D scene with the command line's decomposition flags (as one of
/// `ranks`).
pub fn run(mut s: nscdd::scene::load3::Scene3, scene: &Path, out: &Path, quiet: bool, f: Flags<'_>, ranks: &Ranks) -> ExitCode {
    let movable = (0..s.world.bodies.len()).filter(|&b| s.world.bodies.movable(b)).count();
    let flags =
        crate::apply_decomposition_to(&mut s.decomposition, movable, true, f.subdomains, f.scheme, f.threads).and_then(|()| {
            match f.restart {
                Some(state) => {
                    crate::check_restart_dir(out, state)?;
                    nscdd::scene::restart3::restart3(&mut s.world, state).map_err(|e| e.to_string())
                }
                None => Ok(()),
            }
        });
    let digest = flags.map(|()| {
        let w = &s.world;
        crate::ranks::digest(scene, &nscdd::output::out3::final_json3(w), (&s.decomposition, &w.time, &w.solver))
    });
    if let Err(code) = ranks.agree(digest, out) {
        return code;
    }
    let steps = s.world.time.steps;
    let bar = crate::report::progress(quiet, steps, s.world.step);
    let res = nscdd::run3::run3_on(&mut s, out, ranks.cluster(), |w, rep| {
        crate::report::on_step(&bar, steps, w.step, rep)
    });
    bar.finish_and_clear();
    let dd = |sum: &nscdd::run::RunSummary| match &s.decomposition {
        Some(c) => format!(
            " ({}x{}x{} subdomains, {:?}, {} migrations{})",
            c.dd.nx,
            c.dd.ny,
            c.dd.nz,
            c.dd.scheme,
            sum.migrations,
            crate::report::on_ranks(ranks.size())
        ),
        None => String::new(),
    };
    crate::report::finish_on(ranks, res, s.world.solver.norm.name(), dd, out)
}
