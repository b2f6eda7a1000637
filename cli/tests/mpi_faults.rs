//! Failures on MPI ranks (cargo feature `mpi`): a diverging body stops every rank at
//! the same step, also when only one rank steps it. Needs OpenMPI's `mpirun` (the
//! README's test command installs it).
#![cfg(feature = "mpi")]

mod common;
mod mpi_common;
use common::DIVERGING;
use mpi_common::*;

/// A grain that only one rank steps diverges between two repartitions: every rank
/// stops at the same step, and rank 0 names the body one process names.
#[test]
fn a_diverging_body_stepped_by_one_rank_stops_every_rank() {
    let dir = scratch("diverge_held");
    let body = |x: f64, vx: f64| {
        format!(
            "[[bodies]]\nshape = \"disk\"\nmaterial = \"grain\"\nposition = [{x}, 0.001]\nradius = 1e-3\nvelocity = [{vx:e}, 0.0, 0.0]\n"
        )
    };
    // gravity along x adds 1e98 m/s a step: the fast grain passes 1e100 at step 3
    // (every step steps bodies per rank, the first from a provisional grid over
    // the bodies), the slow one would at step 100
    let scene_text = format!(
        "gravity = [1e101, 0.0]\n[time]\nstep = 1e-3\nsteps = 20\n[[materials]]\nname = \"grain\"\ndensity = 1e3\n\
         [[laws]]\nmaterials = [\"grain\", \"grain\"]\nfriction = 0.0\n[[bodies]]\nshape = \"halfplane\"\nmaterial = \"grain\"\n\
         position = [0.0, 0.0]\nfixed = true\n{}{}",
        body(0.0, 0.0),
        body(0.1, 9.75e99)
    );
    let scene = write(&dir, "diverge.toml", &every(&scene_text, 10));
    let one = nscdd(&args(&scene, &dir.join("one"), &["--subdomains", "2x1"]));
    let one_err = text(&one.stderr);
    assert_eq!(one.status.code(), Some(1), "{one_err}");
    assert!(one_err.contains("step 3") && one_err.contains("body 2"), "{one_err}");
    let out = dir.join("two");
    let o = mpirun(&[(2, args(&scene, &out, &["--subdomains", "2x1"]))]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("step 3") && err.contains("body 2"), "{err}");
    assert_eq!(err.matches("body 2").count(), 1, "rank 0 reports it once: {err}");
    let hist = std::fs::read_to_string(out.join("history.csv")).expect("history.csv kept");
    assert_eq!(hist.lines().count(), 1 + 2, "{hist}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_diverging_body_stops_every_rank_and_keeps_the_outputs() {
    let dir = scratch("diverge");
    // the scene of the one-process test (`common::DIVERGING`) and a grain far away
    let bystander = "[[bodies]]\nname = \"bystander\"\nshape = \"disk\"\nmaterial = \"grain\"\nposition = [0.1, 0.001]\nradius = 1e-3\n";
    let scene = write(&dir, "diverge.toml", &format!("{DIVERGING}\n{bystander}"));
    let out = dir.join("out");
    let o = mpirun(&[(2, args(&scene, &out, &["--subdomains", "2x1"]))]);
    let err = text(&o.stderr);
    println!("{err}");
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("step 6") && err.contains("rocket"), "{err}");
    assert_eq!(err.matches("rocket").count(), 1, "rank 0 reports it once: {err}");
    let hist = std::fs::read_to_string(out.join("history.csv")).expect("history.csv kept");
    assert_eq!(hist.lines().count(), 1 + 5, "{hist}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A panic on one rank while the others step (a plugin's detector, here): that rank
/// prints the message and stops every rank, instead of waiting in `MPI_Finalize`
/// for ranks that wait for it in a collective.
#[test]
fn a_panic_on_one_rank_stops_every_rank() {
    let Some(lib) = nscdd::plugin::built_library("nscdd_plugin_panics") else {
        panic!("libnscdd_plugin_panics is not built: run the tests of the whole workspace (cargo test --workspace --release …)")
    };
    let dir = scratch("panic_one_rank");
    // a fragile bead falling on the floor at x = 0, breaking near it, and four
    // resting at x = 0.5 … 2 (their contacts spread the grid of 2 × 1 subdomains):
    // only the rank of the left cell detects the falling bead
    let mut scene_text = String::from(
        "[time]\nstep = 1e-3\nsteps = 300\n[[materials]]\nname = \"m\"\ndensity = 1000.0\n[[laws]]\n\
         materials = [\"m\", \"m\"]\nfriction = 0.3\n[[bodies]]\nshape = \"halfplane\"\nmaterial = \"m\"\n\
         position = [0.0, 0.0]\nfixed = true\n[[bodies]]\nshape = \"fragile\"\npanic_below = 0.02\n\
         material = \"m\"\nradius = 0.05\nposition = [0.0, 0.1]\n",
    );
    for x in [0.5, 1.0, 1.5, 2.0] {
        scene_text += &format!("[[bodies]]\nshape = \"fragile\"\nmaterial = \"m\"\nradius = 0.05\nposition = [{x}, 0.05]\n");
    }
    let scene = write(&dir, "fragile.toml", &every(&scene_text, 10));
    let lib = lib.display().to_string();
    let o = mpirun(&[(2, args(&scene, &dir.join("two"), &["--subdomains", "2x1", "--plugin", &lib]))]);
    let err = text(&o.stderr);
    assert!(!o.status.success(), "{err}");
    // the message once, from the rank that panicked, with its rank
    assert!(
        (err.contains("rank 0: error: plugin nscdd_plugin_panics") || err.contains("rank 1: error: plugin nscdd_plugin_panics"))
            && err.matches("the fragile bead broke").count() == 1,
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
