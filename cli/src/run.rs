//! `nscdd run`: one driver for 2D and 3D scenes.

use crate::ranks::Ranks;
use nscdd::registry::Registry;
use nscdd::scene::Scene;
use std::path::Path;
use std::process::ExitCode;

/// The command line's flags of a run.
pub struct Flags<'a> {
    pub subdomains: Option<&'a str>,
    pub scheme: Option<&'a str>,
    pub threads: Option<&'a str>,
    pub restart: Option<&'a Path>,
}

/// Runs a loaded scene with the command line's decomposition flags (as one of
/// `ranks`).
pub fn run<D: nscdd::scene::schema::SceneDim>(
    mut s: Scene<D>,
    reg: &Registry,
    scene: &Path,
    out: &Path,
    quiet: bool,
    f: Flags<'_>,
    ranks: &Ranks,
) -> ExitCode {
    // a family's body (a deformable one) may be copied into any number of subdomains
    let movable = match (s.families.is_empty(), &s.survey) {
        (true, Some(sv)) if !sv.families => sv.movable,
        (true, Some(_)) => usize::MAX,
        (true, None) => (0..s.world.bodies.len()).filter(|&b| s.world.bodies.movable(b)).count(),
        (false, _) => usize::MAX,
    };
    let flags = crate::apply_decomposition_to(&mut s.decomposition, movable, D::N == 3, f.subdomains, f.scheme, f.threads).and_then(|()| {
        // a surveyed scene (on ranks): this rank's part, or the whole scene
        let on = (ranks.size(), ranks.rank());
        match f.restart {
            Some(state) => {
                nscdd::scene::restart::check_out_dir(out, state).map_err(|m| format!("--out: {m}"))?;
                // each rank reads the state's contacts its subdomains get, where it can
                nscdd::scene::part::restart_on(&mut s, reg, on, state).map_err(|e| e.to_string())
            }
            None => nscdd::scene::part::load_on(&mut s, reg, on)
                .map(|_| None)
                .map_err(|e| e.to_string()),
        }
    });
    // (what the ranks compare: one process has no one to agree with; contacts read
    // in part differ between ranks: their world is hashed without them, and the
    // digest of every contact the file held, which each rank read, added)
    let digest = flags.map(|in_part| match ranks.size() > 1 {
        true => {
            let (w, dd_state) = (&s.world, &s.dd_state);
            // (the body families' states too: every rank holds them whole)
            let families = (!s.families.is_empty()).then(|| nscdd::family::states(&s.families));
            let state = |out: &mut dyn std::io::Write| {
                let mut none = |_: &mut Vec<f64>| false;
                let contacts: Option<nscdd::output::Pull> = if in_part.is_some() { Some(&mut none) } else { None };
                nscdd::output::write_final_json(out, w, families.as_ref(), dd_state.as_ref(), (contacts, None))
            };
            // (a part: the saved NSCDD state, which chose each rank's bodies and
            // contacts; the families, loaded against each rank's part: their states
            // and descriptions, which count the world bodies they took)
            let nscdd_only = |out: &mut dyn std::io::Write| {
                serde_json::to_writer(&mut *out, dd_state)?;
                serde_json::to_writer(&mut *out, &families)?;
                s.families.iter().try_for_each(|f| out.write_all(f.describe().as_bytes()))
            };
            match s.survey.as_ref().filter(|_| s.world.ids.held().is_some()) {
                // a part: the survey's digest of every body instead of the world's
                Some(sv) => crate::ranks::digest(scene, nscdd_only, (&s.decomposition, &w.time, &w.solver, sv.digest)),
                None => crate::ranks::digest(scene, state, (&s.decomposition, &w.time, &w.solver, in_part)),
            }
        }
        false => 0,
    });
    if let Err(code) = ranks.agree(digest, out) {
        return code;
    }
    let steps = s.world.time.steps;
    let bar = crate::report::progress(quiet, steps, s.world.step);
    let res = nscdd::run::run_on(&mut s, reg, out, ranks.cluster(), |w, rep| {
        crate::report::on_step(&bar, steps, w.step, rep)
    });
    bar.finish_and_clear();
    let dd = |sum: &nscdd::run::RunSummary| match &s.decomposition {
        Some(c) => format!(
            " ({} subdomains, {:?}, {} migrations{})",
            if D::N == 3 {
                format!("{}x{}x{}", c.dd.nx, c.dd.ny, c.dd.nz)
            } else {
                format!("{}x{}", c.dd.nx, c.dd.ny)
            },
            c.dd.scheme,
            sum.migrations,
            crate::report::on_ranks(ranks.size())
        ),
        None => String::new(),
    };
    crate::report::finish_on(ranks, res, s.world.solver.norm.name(), dd, out)
}
