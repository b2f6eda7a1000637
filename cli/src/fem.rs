//! `nscdd run` / `nscdd check` of scenes with `[[deformable]]` bodies (feature
//! `fem`): loaded and run by the deformable plugin.

use nscdd::registry::Registry;
use std::path::Path;
use std::process::ExitCode;

/// Whether the scene file has a `[[deformable]]` entry (a cheap look; the
/// loaders report any error).
pub fn has_deformable(scene: &Path) -> bool {
    std::fs::read_to_string(scene)
        .ok()
        .and_then(|t| toml::from_str::<toml::Table>(&t).ok())
        .is_some_and(|t| t.get("deformable").and_then(|d| d.as_array()).is_some_and(|a| !a.is_empty()))
}

pub fn check(scene: &Path, reg: &Registry) -> ExitCode {
    use nscdd_fem_deformable::scene::FeScene;
    match nscdd_fem_deformable::scene::load_any(scene, reg) {
        Ok(s) => {
            let (dim, rigid, fe, steps, h, by_model) = match &s {
                FeScene::D2(s) => (
                    2,
                    s.world.bodies.len(),
                    &s.fe.bodies,
                    s.world.time.steps,
                    s.world.time.h,
                    s.decomposition.as_ref().map(describe),
                ),
                FeScene::D3(s) => (
                    3,
                    s.world.bodies.len(),
                    &s.fe.bodies,
                    s.world.time.steps,
                    s.world.time.h,
                    s.decomposition.as_ref().map(describe),
                ),
            };
            let nodes: usize = fe.iter().map(|b| b.mesh.n_nodes()).sum();
            println!(
                "{}: ok — {dim}D, {rigid} rigid bodies, {} deformable bodies ({nodes} nodes), {steps} steps of {h} s{}",
                scene.display(),
                fe.len(),
                by_model.map(|d| format!("; {d}")).unwrap_or_default()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// The command line's flags of `nscdd run`.
pub struct Flags<'a> {
    pub subdomains: Option<&'a str>,
    pub scheme: Option<&'a str>,
    pub threads: Option<&'a str>,
    pub restart: bool,
}

/// "subdomains by model, nx × ny cells" (what `check` says of a decomposition).
fn describe(d: &nscdd::dd::DdConfig) -> String {
    let by = if d.by_model { "by model and " } else { "" };
    let grid = if d.dd.nz > 1 {
        format!("{} × {} × {}", d.dd.nx, d.dd.ny, d.dd.nz)
    } else {
        format!("{} × {}", d.dd.nx, d.dd.ny)
    };
    format!(
        "subdomains {by}on a {grid} grid, {} thread(s), {} scheme",
        d.dd.threads,
        match d.dd.scheme {
            nscdd::dd::Scheme::Decentralized => "decentralized",
            nscdd::dd::Scheme::Centralized => "centralized",
        }
    )
}

pub fn run(scene: &Path, out: &Path, quiet: bool, reg: &Registry, flags: Flags<'_>) -> ExitCode {
    use nscdd_fem_deformable::scene::FeScene;
    let refuse = |flag: &str, why: &str| {
        eprintln!("error: {flag} is not supported for scenes with deformable bodies yet ({why})");
        ExitCode::from(2)
    };
    if flags.restart {
        return refuse("--restart", "their state is not checkpointed");
    }
    let ranks = crate::ranks::launched_size();
    if ranks > 1 {
        eprintln!(
            "error: started as one of {ranks} MPI ranks, but scenes with deformable bodies run in one process for now (use --threads): run without mpirun"
        );
        return ExitCode::from(2);
    }
    let apply = |d: &mut Option<nscdd::dd::DdConfig>, movable: usize, dim3: bool| {
        crate::apply_decomposition_to(d, movable, dim3, flags.subdomains, flags.scheme, flags.threads).map_err(|m| {
            eprintln!("error: {m}");
            ExitCode::from(2)
        })
    };
    match nscdd_fem_deformable::scene::load_any(scene, reg) {
        Ok(FeScene::D2(mut s)) => {
            // a deformable body may be copied into any number of subdomains: no bound
            if let Err(code) = apply(&mut s.decomposition, usize::MAX, false) {
                return code;
            }
            run_loaded(&mut s, out, quiet)
        }
        Ok(FeScene::D3(mut s)) => {
            if let Err(code) = apply(&mut s.decomposition, usize::MAX, true) {
                return code;
            }
            run_loaded(&mut s, out, quiet)
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn run_loaded<S: nscdd_fem_deformable::run::FeRunnable>(s: &mut S, out: &Path, quiet: bool) -> ExitCode {
    let bar = (!quiet).then(|| indicatif::ProgressBar::new(s.clock().2));
    let r = nscdd_fem_deformable::run::run(s, out, |k, _| {
        if let Some(b) = &bar {
            b.set_position(k)
        }
    });
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    match r {
        Ok(sum) => {
            if !quiet {
                println!(
                    "{} steps in {:.2} s, {} sweeps; outputs in {}",
                    sum.steps,
                    sum.wall_seconds,
                    sum.total_sweeps,
                    out.display()
                );
            }
            if sum.unconverged_steps > 0 {
                eprintln!(
                    "warning: the contact solver did not converge in {} of {} steps; see the `converged` column of history.csv",
                    sum.unconverged_steps, sum.steps
                );
            }
            ExitCode::SUCCESS
        }
        Err(m) => {
            eprintln!("error: {m}");
            ExitCode::from(1)
        }
    }
}
