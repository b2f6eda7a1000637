//! Scenes that crashed, aborted or hung `nscdd check` in a mutation campaign (issue
//! 17), each the example scene with one line changed: now exit 2 with one message
//! naming the file, the line and the key, before anything large is allocated.

mod common;
use common::*;

/// `examples/scenes/NAME` with `from` replaced by `to` (once), checked.
fn check_mutant(name: &str, from: &str, to: &str, extra: &[&str]) -> (Option<i32>, String) {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = scratch(&format!("limits-{k}-{}", name.replace('.', "_")));
    let text = std::fs::read_to_string(format!("{}/../examples/scenes/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap();
    assert!(text.contains(from), "{name}: `{from}` not found");
    let path = dir.join(name);
    std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
    let mut args: Vec<&std::ffi::OsStr> = vec!["check".as_ref(), path.as_os_str()];
    args.extend(extra.iter().map(|a| std::ffi::OsStr::new(a)));
    let o = nscdd(&args);
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[track_caller]
fn refused(name: &str, from: &str, to: &str, key: &str, said: &str) {
    // a fixed limit: the same outcome on any machine
    let (code, err) = check_mutant(name, from, to, &["--max-memory", "16G"]);
    assert_eq!(code, Some(2), "{name} with `{to}`: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains(&format!("key `{key}`")), "{name} with `{to}`: {err}");
    assert!(err.contains(said), "{name} with `{to}`: {err}");
    assert_eq!(err.lines().count(), 1, "one message: {err}");
}

#[test]
fn huge_counts_are_refused_with_the_estimate() {
    // each hung for minutes (allocating and placing 10⁸ bodies)
    refused(
        "aqueduct.toml",
        "voussoirs = 16",
        "voussoirs = 100000000",
        "generate[6].voussoirs",
        "needs ≈",
    );
    refused(
        "triaxial3d.toml",
        "count = 1000",
        "count = 100000000",
        "generate[0].count",
        "needs ≈",
    );
    refused("wall.toml", "courses = 10", "courses = 100000000", "generate[0].courses", "needs ≈");
    refused("deposit.toml", "count = 1000", "count = 1000000000000", "generate[0].count", "PB");
}

#[test]
fn huge_boxes_are_refused_before_their_grids() {
    // a range panic (cols.len() overflowed to 0), an abort on a 1 TB allocation,
    // and a capacity overflow, in the generators' neighbour grids
    refused(
        "deposit.toml",
        "box = [0.0, 0.0, 1.0, 1.2]",
        "box = [0.0, 0.0, 1e308, 1.2]",
        "generate[0].box",
        "grid",
    );
    refused(
        "deposit.toml",
        "box = [0.0, 0.0, 1.0, 1.2]",
        "box = [0.0, 0.0, 1e9, 1.2]",
        "generate[0].box",
        "grid",
    );
    refused(
        "triaxial3d.toml",
        "box = [0.0, 0.0, 0.0, 0.13, 0.13, 0.13]",
        "box = [0.0, -1e308, 0.0, 0.13, 0.13, 0.13]",
        "generate[0].box",
        "grid",
    );
}

#[test]
fn a_polyhedron_flattened_by_round_off_is_an_input_error() {
    // an arch 10⁹ m from the origin: its faces lost their area (index out of bounds
    // in hull.rs)
    refused(
        "aqueduct.toml",
        "origin = [2.6, 0.0, 2.5]",
        "origin = [1e9, 0.0, 2.5]",
        "generate[7].kind",
        "too flat",
    );
}

#[test]
fn max_memory_sets_the_limit() {
    let (code, err) = check_mutant("deposit.toml", "count = 1000", "count = 1000", &["--max-memory", "1M"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--max-memory"), "{err}");
    let (code, err) = check_mutant("deposit.toml", "count = 1000", "count = 1000", &["--max-memory", "1G"]);
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = check_mutant("deposit.toml", "count = 1000", "count = 1000", &["--max-memory", "lots"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--max-memory"), "{err}");
}

#[test]
#[cfg(feature = "fem")]
fn huge_meshes_are_refused_before_python_builds_them() {
    // 10¹⁰ nodes: numpy's allocation failure came back as a Python traceback
    refused(
        "foundation.toml",
        "cells = [40, 10]",
        "cells = [100000, 100000]",
        "deformable[0].mesh",
        "needs ≈ 60 TB (a deformable body of about 10000200001 nodes)",
    );
    // 2.3 × 10⁵ nodes in 3D: minutes of assembly and factorization, tens of GB
    let (code, err) = check_mutant(
        "foundation3d.toml",
        "cells = [10, 10, 3]",
        "cells = [60, 60, 60]",
        &["--max-memory", "1G"],
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("key `deformable[0].mesh`") && err.contains("--max-memory"), "{err}");
    // the example itself fits in 1 GiB
    let (code, err) = check_mutant(
        "foundation3d.toml",
        "cells = [10, 10, 3]",
        "cells = [10, 10, 3]",
        &["--max-memory", "1G"],
    );
    assert_eq!(code, Some(0), "{err}");
}

/// Mutants whose accepted runs hung in the campaign with runs (issue 17).
#[test]
fn an_alert_distance_that_makes_every_pair_a_contact_is_refused() {
    // 2000 disks with alert = 2 m: 2·10⁶ contacts per step, minutes per step
    refused(
        "biaxial.toml",
        "alert = 5e-4",
        "alert = 2.0",
        "detection.alert",
        "contact candidates",
    );
}

#[test]
fn densities_in_the_subnormal_range_are_refused() {
    // ρ = 1e308: inverse masses of 10⁻³⁰⁸, 20 000 sweeps per step on subnormal numbers
    refused(
        "aqueduct.toml",
        "density = 2200.0",
        "density = 1e308",
        "materials[0].density",
        "[1e-20, 1e20]",
    );
    refused(
        "aqueduct.toml",
        "density = 2200.0",
        "density = 1e-300",
        "materials[0].density",
        "[1e-20, 1e20]",
    );
}

#[test]
fn an_overflowing_run_stops_at_its_first_step_naming_the_body() {
    // g = 1e308: velocities of 10³⁰⁵ after one step; the solver swept on infinities
    // for a minute per step before its sums were checked
    let dir = scratch("overflow");
    let text = std::fs::read_to_string(format!("{}/../examples/scenes/aqueduct.toml", env!("CARGO_MANIFEST_DIR"))).unwrap();
    let path = dir.join("aqueduct.toml");
    std::fs::write(
        &path,
        text.replacen("gravity = [0.0, 0.0, -9.81]", "gravity = [0.0, 1e308, -9.81]", 1),
    )
    .unwrap();
    let t0 = std::time::Instant::now();
    let o = nscdd(&[
        "run".as_ref(),
        path.as_os_str(),
        "--out".as_ref(),
        dir.join("out").as_os_str(),
        "--quiet".as_ref(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("diverged at step 1") && err.contains("body"), "{err}");
    assert!(t0.elapsed().as_secs() < 10, "took {:?}", t0.elapsed());
    assert!(dir.join("out/history.csv").exists());
}

#[test]
fn bodies_too_small_to_have_a_mass_are_refused() {
    // a disk of 1e-200 m (a sphere of 1e-308 m in the deformable fuzz target): a mass
    // of 0, an infinite inverse mass, NaN at the first step
    let dir = scratch("massless");
    let path = dir.join("s.toml");
    std::fs::write(&path, edit(BASE, "radius = 0.1", "radius = 1e-200")).unwrap();
    let o = nscdd(&["check".as_ref(), path.as_os_str()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("key `bodies[1].shape`") && err.contains("mass (0)"), "{err}");
    // the same made by a generator
    let lattice = "[[generate]]\nkind = \"square_lattice\"\nmaterial = \"grain\"\nradius = 1e-200\norigin = [1.0, 1.0]\nnx = 2\nny = 2\nspacing = 0.5\n";
    std::fs::write(&path, format!("{BASE}{lattice}")).unwrap();
    let o = nscdd(&["check".as_ref(), path.as_os_str()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("key `generate[0]`") && err.contains("mass 0e0"), "{err}");
    // and a generator's grid of such disks is refused by its size, in scientific notation
    let (code, err) = check_mutant(
        "deposit.toml",
        "radius_min = 0.008\nradius_max = 0.012",
        "radius_min = 1e-200\nradius_max = 1e-200",
        &["--max-memory", "16G"],
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("e201 B"), "{err}");
}

/// The two runs the campaign of 20 000 mutants with runs (seed 41) found over 20 s.
#[test]
fn an_alert_of_every_pair_in_3d_and_an_unreachable_tolerance_are_refused() {
    // 1000 spheres with alert = 2 m: 5·10⁵ contacts per step
    refused(
        "triaxial3d.toml",
        "alert = 0.0005",
        "alert = 2",
        "detection.alert",
        "contact candidates",
    );
    // tolerance 1e-300: every step ran to max_sweeps (20 000 in the aqueduct)
    refused(
        "aqueduct.toml",
        "tolerance = 1.666e-4",
        "tolerance = 1e-300",
        "solver.tolerance",
        "≥ 1e-15",
    );
}
