//! `nscdd`: run, check and benchmark scenes; solve frictional contact problems.
//!
//! Exit codes: 0 success; 1 a run that stopped (divergence, unwritable output);
//! 2 bad input (the message names the file, the line and the key).

mod bench;
mod plugins;
mod ranks;
mod report;
mod run;

use clap::{Parser, Subcommand};
use nscdd::dim::{D2, D3};
use nscdd::fc::{FcNorm, FcOptions};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "nscdd", version, about = "Non-smooth contact dynamics with domain decomposition")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
    /// Memory a scene may use (e.g. 8G, 500M; default: the memory available on this
    /// machine): a generator asked for more bodies is refused before it allocates.
    #[arg(long, global = true)]
    max_memory: Option<String>,
    /// A plugin library to load (repeatable; docs/PLUGINS.md). Scenes may also name
    /// theirs in `[[plugins]] library = "…"`.
    #[arg(long, global = true, value_name = "PATH")]
    plugin: Vec<PathBuf>,
}

/// `nscdd solve-fc`'s options.
#[derive(clap::Args)]
struct SolveFcArgs {
    problem: PathBuf,
    /// Tolerance of the stopping test.
    #[arg(long, default_value_t = 1e-6)]
    tol: f64,
    #[arg(long, default_value_t = 10000)]
    max_sweeps: u32,
    /// `nlgs`, `anderson` (Anderson-accelerated NLGS) or `newton` (semismooth Newton, Alart–Curnier)
    #[arg(long, default_value = "nlgs")]
    method: String,
    /// `natural` (‖F(r)‖/‖q‖ < tol), `Quad`, `Maxm` or `QM/16`.
    #[arg(long, default_value = "natural")]
    norm: String,
    /// Check the stopping test every k sweeps.
    #[arg(long, default_value_t = 1)]
    check_every: u32,
    /// ω of the NLGS sweeps (`nlgs`, and `anderson`'s map), in (0, 2): below 1
    /// under-relaxed, above 1 over-relaxed and projected on the Coulomb cones.
    #[arg(long, default_value_t = 1.0)]
    relaxation: f64,
    /// Also write the problem as read (FCLIB global problems: condensed) in the
    /// JSON exchange format (`.gz`: compressed).
    #[arg(long, value_name = "FILE")]
    export_json: Option<PathBuf>,
    /// Solve N times and report the fastest `solve_seconds` (benchmarks: the
    /// first solve of a process also pays for its first touches of memory).
    #[arg(long, default_value_t = 1)]
    repeat: u32,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run a scene and write history.csv, final.json and VTK files in DIR.
    Run {
        scene: PathBuf,
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// NSCDD over NXxNY subdomains (e.g. 2x2; NXxNYxNZ in 3D); overrides
        /// [decomposition].
        #[arg(long, value_name = "NXxNY", allow_hyphen_values = true)]
        subdomains: Option<String>,
        /// Gluing scheme: decentralized or centralized (needs a decomposition).
        #[arg(long, allow_hyphen_values = true)]
        scheme: Option<String>,
        /// Threads sweeping the subdomains (needs a decomposition).
        #[arg(long, value_name = "N", allow_hyphen_values = true)]
        threads: Option<String>,
        /// Continue from a saved state (a run's final.json or checkpoint.json) of the
        /// same scene, to the scene's end time.
        #[arg(long, value_name = "STATE")]
        restart: Option<PathBuf>,
    },
    /// Validate a scene without running it.
    Check { scene: PathBuf },
    /// List the plugins (built in, and loaded with --plugin) and what each registers.
    Plugins,
    /// Solve one frictional contact problem (JSON exchange format) and print JSON.
    SolveFc(SolveFcArgs),
    /// Run a scene (2D or 3D) for N steps and write the local problem of its last
    /// step in the JSON exchange format (`.gz`: compressed).
    ExportFc {
        scene: PathBuf,
        #[arg(long)]
        steps: u64,
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
    /// Benchmarks: `nlgs` (contact updates per second), `deposit` (time per stage) or
    /// `nscdd` (NSCDD iterations and thread efficiency on the compacted biaxial sample).
    Bench {
        #[arg(value_parser = ["nlgs", "nlgs3", "deposit", "nscdd"])]
        which: String,
        /// Number of disks (default 10000; nscdd: 2000).
        #[arg(long)]
        disks: Option<usize>,
        /// Sweeps (nlgs) or steps (deposit, nscdd) to time (default 200; nscdd: 20).
        #[arg(long)]
        repeat: Option<usize>,
        /// nscdd: decompositions, comma-separated NXxNY.
        #[arg(long, value_name = "LIST", default_value = "1x1,2x1,2x2,3x3,4x4")]
        subdomains: String,
    },
}

pub(crate) fn input_error(e: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(2)
}

/// `NXxNY` (or `NXxNYxNZ` for 3D scenes) with integers ≥ 1.
fn parse_subdomains(v: &str) -> Result<(u32, u32), String> {
    match parse_subdomains3(v)? {
        (nx, ny, 1) if v.matches(['x', 'X']).count() == 1 => Ok((nx, ny)),
        _ => Err(format!(
            "--subdomains: expected NXxNY with integers NX, NY ≥ 1 (e.g. 2x2), got `{v}`"
        )),
    }
}

/// `NXxNY` or `NXxNYxNZ` with integers ≥ 1.
fn parse_subdomains3(v: &str) -> Result<(u32, u32, u32), String> {
    let bad = || format!("--subdomains: expected NXxNY or NXxNYxNZ with integers ≥ 1 (e.g. 2x2 or 2x2x1), got `{v}`");
    let parts: Vec<&str> = v.split(['x', 'X']).collect();
    let n = |t: &str| t.trim().parse::<u32>().ok().filter(|&k| k >= 1);
    match parts.as_slice() {
        [a, b] => Ok((n(a).ok_or_else(bad)?, n(b).ok_or_else(bad)?, 1)),
        [a, b, c] => Ok((n(a).ok_or_else(bad)?, n(b).ok_or_else(bad)?, n(c).ok_or_else(bad)?)),
        _ => Err(bad()),
    }
}

/// The command line's decomposition flags over a scene's `[decomposition]` (`dim3`:
/// NXxNYxNZ accepted).
pub(crate) fn apply_decomposition_to(
    decomposition: &mut Option<nscdd::dd::DdConfig>,
    movable: usize,
    dim3: bool,
    subdomains: Option<&str>,
    scheme: Option<&str>,
    threads: Option<&str>,
) -> Result<(), String> {
    if let Some(v) = subdomains {
        let (nx, ny, nz) = if dim3 {
            parse_subdomains3(v)?
        } else {
            let (nx, ny) = parse_subdomains(v)?;
            (nx, ny, 1)
        };
        let c = decomposition.get_or_insert_with(Default::default);
        c.dd.nx = nx;
        c.dd.ny = ny;
        c.dd.nz = nz;
    }
    for (flag, given) in [("--scheme", scheme.is_some()), ("--threads", threads.is_some())] {
        if given && decomposition.is_none() {
            return Err(format!(
                "{flag} needs a decomposition: give --subdomains NXxNY or a [decomposition] section"
            ));
        }
    }
    let Some(c) = decomposition.as_mut() else {
        return Ok(());
    };
    if let Some(v) = scheme {
        c.dd.scheme = nscdd::scene::parse_scheme(v).map_err(|m| format!("--scheme: {m}"))?;
    }
    if let Some(v) = threads {
        c.dd.threads = v
            .trim()
            .parse::<usize>()
            .ok()
            .filter(|&t| t >= 1)
            .ok_or_else(|| format!("--threads: expected an integer ≥ 1, got `{v}`"))?;
    }
    if subdomains.is_some() {
        c.check_capacity(movable).map_err(|(_, m)| format!("--subdomains: {m}"))?;
    }
    Ok(())
}

/// Writes a problem in the JSON exchange format (gzip for `.gz`).
fn write_problem(p: &nscdd::fc::FcProblem, path: &std::path::Path) -> Result<(), String> {
    use std::io::Write;
    let err = |e: std::io::Error| format!("cannot write {}: {e}", path.display());
    let f = std::fs::File::create(path).map_err(err)?;
    if path.to_string_lossy().ends_with(".gz") {
        let mut z = flate2::write::GzEncoder::new(f, flate2::Compression::fast());
        z.write_all(p.to_json().as_bytes()).map_err(err)?;
        z.finish().map_err(err)?;
    } else {
        let mut w = std::io::BufWriter::new(f);
        w.write_all(p.to_json().as_bytes()).map_err(err)?;
        w.flush().map_err(err)?;
    }
    Ok(())
}

fn main() -> ExitCode {
    plugins::install_panic_hook();
    // a panic (in a plugin's code or ours) stops the command with its message
    std::panic::catch_unwind(command).unwrap_or_else(plugins::report)
}

fn command() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let mut reg = nscdd_rigid_disks::registry();
    reg.add_plugin(&nscdd_spheres::SpheresPlugin);
    reg.add_plugin(&nscdd_polyhedra::PolyhedraPlugin);
    #[cfg(feature = "fem")]
    reg.add_plugin(&nscdd_fem_deformable::FemPlugin);
    if let Some(m) = &cli.max_memory {
        match nscdd::registry::limits::parse_size(m) {
            Ok(bytes) => reg.set_max_memory(bytes),
            Err(e) => return input_error(e),
        }
    }
    if let Err(e) = plugins::load_cli(&cli.plugin, &mut reg) {
        return input_error(e);
    }
    // the plugins a scene names, loaded before it is read
    let scene_of = match &cli.cmd {
        Cmd::Check { scene } | Cmd::Run { scene, .. } | Cmd::ExportFc { scene, .. } => Some(scene.clone()),
        _ => None,
    };
    if let Some(scene) = scene_of {
        if let Err(e) = plugins::load_for_scene(&scene, &mut reg) {
            return input_error(e);
        }
    }
    let reg = reg;
    match cli.cmd {
        Cmd::Plugins => plugins::list(&reg),
        Cmd::Check { scene } => check(&scene, &reg),
        Cmd::Run {
            scene,
            out,
            quiet,
            subdomains,
            scheme,
            threads,
            restart,
        } => {
            let ranks = match ranks::Ranks::start() {
                Ok(r) => r,
                Err(e) => return input_error(e),
            };
            let quiet = quiet || !ranks.root();
            stop_on_signals();
            let flags = run::Flags {
                subdomains: subdomains.as_deref(),
                scheme: scheme.as_deref(),
                threads: threads.as_deref(),
                restart: restart.as_deref(),
            };
            // on ranks, a scene is first surveyed: each rank then builds its part
            let loaded = match ranks.size() > 1 {
                true => survey_any(&scene, &reg),
                false => load_any(&scene, &reg),
            };
            match loaded {
                Ok(nscdd::scene::AnyScene::D2(s)) => run::run(s, &reg, &scene, &out, quiet, flags, &ranks),
                Ok(nscdd::scene::AnyScene::D3(s)) => run::run(s, &reg, &scene, &out, quiet, flags, &ranks),
                // every rank learns that a rank failed; rank 0 prints the message
                Err(e) => ranks.agree(Err(e.to_string()), &out).err().unwrap_or(ExitCode::from(2)),
            }
        }
        Cmd::SolveFc(a) => solve_fc(&a),
        Cmd::ExportFc { scene, steps, out } => export_fc(&scene, steps, &out, &reg),
        Cmd::Bench {
            which,
            disks,
            repeat,
            subdomains,
        } => bench_command(&reg, &which, disks, repeat, &subdomains),
    }
}

/// `nscdd bench WHICH`: the benchmark named, its figures on stdout.
fn bench_command(reg: &nscdd::registry::Registry, which: &str, disks: Option<usize>, repeat: Option<usize>, subdomains: &str) -> ExitCode {
    let done = match which {
        "nlgs" => bench::nlgs::<D2>(reg, "nlgs", &bench::lattice(disks.unwrap_or(10000)), repeat.unwrap_or(200)),
        "nlgs3" => bench::nlgs::<D3>(reg, "nlgs3", &bench::lattice3(disks.unwrap_or(10648)), repeat.unwrap_or(200)),
        "deposit" => bench::deposit(reg, disks.unwrap_or(10000), repeat.unwrap_or(200)),
        _ => {
            let list: Result<Vec<_>, _> = subdomains.split(',').map(parse_subdomains).collect();
            match list {
                Ok(list) => bench::nscdd(reg, disks.unwrap_or(2000), repeat.unwrap_or(20), &list),
                Err(e) => return input_error(e),
            }
        }
    };
    if let Err(e) = done {
        eprintln!("error: {e}");
        return ExitCode::from(e.exit_code());
    }
    ExitCode::SUCCESS
}

/// SIGINT/SIGTERM stop a run at the end of its current step with a checkpoint
/// (`nscdd::run::request_stop`); a second one ends the process at once. On MPI
/// ranks, a signal on any rank stops every rank after the same step.
fn stop_on_signals() {
    static SEEN: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
    let _ = ctrlc::set_handler(|| {
        if SEEN.swap(true, std::sync::atomic::Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("\nstopping at the end of this step (a checkpoint is written); a second signal ends the run at once");
        nscdd::run::request_stop();
    });
}

/// Loads a scene of either dimension; a scene with deformable bodies given to a
/// program built without them gets the way to build it.
pub(crate) fn load_any(
    scene: &std::path::Path,
    reg: &nscdd::registry::Registry,
) -> Result<nscdd::scene::AnyScene, nscdd::error::InputError> {
    nscdd::scene::load_any(scene, reg).map_err(fem_hint)
}

/// [`load_any`] on MPI ranks: the scene's survey ([`nscdd::scene::part`]; each rank
/// builds its part once the decomposition flags apply), or the whole scene for one
/// with a body family that gives no load boxes.
fn survey_any(scene: &std::path::Path, reg: &nscdd::registry::Registry) -> Result<nscdd::scene::AnyScene, nscdd::error::InputError> {
    match nscdd::scene::part::survey_any(scene, reg).map_err(fem_hint)? {
        Some(s) => Ok(s),
        None => load_any(scene, reg),
    }
}

/// A scene with deformable bodies given to a program built without them: the way
/// to build it.
fn fem_hint(mut e: nscdd::error::InputError) -> nscdd::error::InputError {
    if e.key == "deformable" && !cfg!(feature = "fem") {
        e.message = "deformable bodies need the fem_deformable plugin: build nscdd with `cargo build --release --features nscdd-cli/fem` (and Python's scikit-fem, see the README)".into();
    }
    e
}

/// What `check` says of a scene's body families ("; 2 deformable bodies (…)").
fn families_line<D: nscdd::dim::Dim>(s: &nscdd::scene::Scene<D>) -> String {
    s.families.iter().map(|f| format!(", {}", f.describe())).collect()
}

/// `nscdd check`: load, validate and describe a scene.
fn check(scene: &std::path::Path, reg: &nscdd::registry::Registry) -> ExitCode {
    match load_any(scene, reg) {
        Ok(nscdd::scene::AnyScene::D3(s)) => {
            let w = &s.world;
            let dd = match &s.decomposition {
                Some(c) => format!(
                    "; NSCDD {}x{}x{} subdomains{}, {:?}",
                    c.dd.nx,
                    c.dd.ny,
                    c.dd.nz,
                    if c.by_model { " by model" } else { "" },
                    c.dd.scheme
                ),
                None => String::new(),
            };
            println!(
                "{}: ok — 3D, {} rigid bodies{}, {} steps of {} s{dd}",
                scene.display(),
                w.bodies.len(),
                families_line(&s),
                w.time.steps,
                w.time.h
            );
            ExitCode::SUCCESS
        }
        Ok(nscdd::scene::AnyScene::D2(s)) => {
            let w = &s.world;
            let dd = match &s.decomposition {
                Some(c) => format!(
                    "; NSCDD {}x{} subdomains{}, {:?}, repartition every {} steps",
                    c.dd.nx,
                    c.dd.ny,
                    if c.by_model { " by model" } else { "" },
                    c.dd.scheme,
                    c.repartition_every
                ),
                None => String::new(),
            };
            println!(
                "{}: ok — {} rigid bodies{}, {} steps of {} s{dd}",
                scene.display(),
                w.bodies.len(),
                families_line(&s),
                w.time.steps,
                w.time.h
            );
            ExitCode::SUCCESS
        }
        Err(e) => input_error(e),
    }
}

/// `nscdd solve-fc`: one frictional-contact problem, solved and printed as JSON.
fn solve_fc(a: &SolveFcArgs) -> ExitCode {
    let (tol, max_sweeps, check_every) = (a.tol, a.max_sweeps, a.check_every);
    let Some(method) = nscdd::solver::Method::parse(&a.method) else {
        return input_error(format!(
            "--method: unknown method `{}`; expected nlgs, anderson or newton",
            a.method
        ));
    };
    let Some(norm) = FcNorm::parse(&a.norm) else {
        return input_error(format!("--norm: unknown norm `{}`; expected natural, Quad, Maxm or QM/16", a.norm));
    };
    if !(tol > 0.0) || max_sweeps == 0 || check_every == 0 || a.repeat == 0 {
        return input_error("--tol must be > 0, --max-sweeps, --check-every and --repeat ≥ 1");
    }
    if !(a.relaxation > 0.0 && a.relaxation < 2.0) {
        return input_error(format!("--relaxation: ω must lie in (0, 2), got {}", a.relaxation));
    }
    if method == nscdd::solver::Method::Newton && a.relaxation != 1.0 {
        return input_error("--relaxation: `newton` takes no relaxation (use nlgs or anderson)");
    }
    let p = match nscdd::fc::read_any(&a.problem) {
        Ok(p) => p,
        Err(e) => return input_error(e),
    };
    if let Some(path) = &a.export_json {
        if let Err(e) = write_problem(&p, path) {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
    }
    let opts = FcOptions {
        tol,
        max_sweeps,
        check_every,
        norm,
        method,
        relaxation: a.relaxation,
    };
    let mut sol = p.solve(&opts);
    for _ in 1..a.repeat {
        let again = p.solve(&opts);
        sol.solve_seconds = sol.solve_seconds.min(again.solve_seconds);
    }
    println!("{}", serde_json::to_string(&sol).expect("plain data"));
    if !sol.converged {
        eprintln!(
            "warning: not converged after {} iterations (residual {:e})",
            sol.sweeps, sol.residual
        );
    }
    ExitCode::SUCCESS
}

/// The local problem of a scene after `steps` steps, stepped as a run without a
/// decomposition would (its body families' one-domain stage, or NSCDD on one
/// subdomain): the world's contacts, then each family's.
fn export_scene<D: nscdd::dim::Dim>(mut s: nscdd::scene::Scene<D>, steps: u64) -> Result<nscdd::fc::FcProblem, ExitCode> {
    let one = nscdd::dd::DdConfig::default();
    let mut dd = nscdd::family::needs_nscdd(false, &mut s.families).then(|| one.solver_of());
    for _ in 0..steps {
        let mut fams: Vec<&mut dyn nscdd::family::SceneFamily<D>> = s.families.iter_mut().map(|f| &mut **f).collect();
        if let Err(e) = nscdd::family::step(&mut s.world, &mut fams, dd.as_mut()) {
            eprintln!("error: {e}");
            return Err(ExitCode::from(1));
        }
    }
    let bonded = s.world.contacts.joint.iter().filter(|j| j.bonded()).count();
    if bonded > 0 {
        eprintln!(
            "error: {bonded} contacts are intact mortar joints (law `mohr_coulomb`): a frictional-contact problem (FCLIB) cannot express their cohesion"
        );
        return Err(ExitCode::from(2));
    }
    nscdd::family::local_problem(&s.world, &s.families).map_err(input_error)
}

/// `nscdd export-fc`: the contact problem of a scene after `steps` steps.
fn export_fc(scene: &std::path::Path, steps: u64, out: &std::path::Path, reg: &nscdd::registry::Registry) -> ExitCode {
    let p = match load_any(scene, reg) {
        Err(e) => return input_error(e),
        Ok(nscdd::scene::AnyScene::D2(s)) => export_scene(s, steps),
        Ok(nscdd::scene::AnyScene::D3(s)) => export_scene(s, steps),
    };
    let p = match p {
        Ok(p) => p,
        Err(code) => return code,
    };
    match write_problem(&p, out) {
        Ok(()) => {
            eprintln!("{} contacts (dim {}) written to {}", p.nc, p.dim, out.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}
