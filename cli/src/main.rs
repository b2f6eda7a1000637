//! `nscdd`: run, check and benchmark scenes; solve frictional contact problems.
//!
//! Exit codes: 0 success; 1 a run that stopped (divergence, unwritable output);
//! 2 bad input (the message names the file, the line and the key).

mod bench;

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use nscdd::fc::{FcNorm, FcOptions};
use nscdd::norms::Criterion;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "nscdd", version, about = "Non-smooth contact dynamics with domain decomposition")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
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
    },
    /// Validate a scene without running it.
    Check { scene: PathBuf },
    /// Solve one frictional contact problem (JSON exchange format) and print JSON.
    SolveFc {
        problem: PathBuf,
        /// Tolerance of the stopping test.
        #[arg(long, default_value_t = 1e-6)]
        tol: f64,
        #[arg(long, default_value_t = 10000)]
        max_sweeps: u32,
        /// `natural` (‖F(r)‖/‖q‖ < tol), `Quad`, `Maxm` or `QM/16`.
        #[arg(long, default_value = "natural")]
        norm: String,
        /// Check the stopping test every k sweeps.
        #[arg(long, default_value_t = 1)]
        check_every: u32,
    },
    /// Benchmarks: `nlgs` (contact updates per second) or `deposit` (time per stage).
    Bench {
        #[arg(value_parser = ["nlgs", "deposit"])]
        which: String,
        /// Number of disks.
        #[arg(long, default_value_t = 10000)]
        disks: usize,
        /// Sweeps (nlgs) or steps (deposit) to time.
        #[arg(long, default_value_t = 200)]
        repeat: usize,
    },
}

fn input_error(e: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(2)
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let reg = nscdd_rigid_disks::registry();
    match cli.cmd {
        Cmd::Check { scene } => match nscdd::scene::load(&scene, &reg) {
            Ok(s) => {
                let w = &s.world;
                println!(
                    "{}: ok — {} bodies, {} steps of {} s",
                    scene.display(),
                    w.bodies.len(),
                    w.time.steps,
                    w.time.h
                );
                ExitCode::SUCCESS
            }
            Err(e) => input_error(e),
        },
        Cmd::Run { scene, out, quiet } => {
            let mut s = match nscdd::scene::load(&scene, &reg) {
                Ok(s) => s,
                Err(e) => {
                    // nothing in DIR but the error
                    if std::fs::create_dir_all(&out).is_ok() {
                        let _ = std::fs::write(out.join("error.txt"), format!("{e}\n"));
                    }
                    return input_error(e);
                }
            };
            let steps = s.world.time.steps;
            let bar = if quiet { ProgressBar::hidden() } else { ProgressBar::new(steps) };
            bar.set_style(
                ProgressStyle::with_template("{bar:30} step {pos}/{len} | {msg} | {elapsed_precise} elapsed, {eta_precise} left")
                    .expect("valid template"),
            );
            let res = nscdd::run::run(&mut s, &reg, &out, |w, rep| {
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
                    if sum.unconverged_steps > 0 {
                        eprintln!(
                            "warning: the contact solver did not converge in {} of {} steps (first: step {}); see the `converged` column of history.csv",
                            sum.unconverged_steps,
                            sum.steps,
                            sum.first_unconverged.unwrap_or(0)
                        );
                    }
                    if sum.suspect_steps > 0 {
                        eprintln!(
                            "warning: {} steps met the {} criterion with a natural-map residual above {} × tolerance (largest {:.2e} at step {}): the solve stalled; lower solver.tolerance (docs/EXTREMES.md)",
                            sum.suspect_steps,
                            s.world.solver.norm.name(),
                            nscdd::run::SUSPECT_FACTOR,
                            sum.max_residual,
                            sum.max_residual_step
                        );
                    }
                    eprintln!(
                        "{} steps, {} sweeps, {:.2} s; outputs in {}",
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
        Cmd::SolveFc {
            problem,
            tol,
            max_sweeps,
            norm,
            check_every,
        } => {
            let norm = match norm.as_str() {
                "natural" => FcNorm::Natural,
                other => match Criterion::parse(other) {
                    Some(c) => FcNorm::Lmgc(c),
                    None => return input_error(format!("--norm: unknown norm `{other}`; expected natural, Quad, Maxm or QM/16")),
                },
            };
            if !(tol > 0.0) || max_sweeps == 0 || check_every == 0 {
                return input_error("--tol must be > 0, --max-sweeps and --check-every ≥ 1");
            }
            match nscdd::fc::solve_file(
                &problem,
                &FcOptions {
                    tol,
                    max_sweeps,
                    check_every,
                    norm,
                },
            ) {
                Ok(sol) => {
                    println!("{}", serde_json::to_string(&sol).expect("plain data"));
                    if !sol.converged {
                        eprintln!("warning: not converged after {} sweeps (residual {:e})", sol.sweeps, sol.residual);
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => input_error(e),
            }
        }
        Cmd::Bench { which, disks, repeat } => {
            match which.as_str() {
                "nlgs" => bench::nlgs(&reg, disks, repeat),
                _ => bench::deposit(&reg, disks, repeat),
            }
            ExitCode::SUCCESS
        }
    }
}
