//! The `nscdd` binary on malformed scenes and on a diverging run.
//!
//! Every malformed scene must give exit code 2 and one message on stderr,
//! `error: FILE:LINE: key `KEY`: ...`, naming the file, the line of the offending key
//! and the key's full path, without a panic; `nscdd run SCENE --out DIR` must then
//! leave nothing in DIR but `error.txt` (holding the same message). A run that
//! diverges must stop with exit code 1, name the step and the body, and keep the
//! `history.csv` written so far.

use std::path::PathBuf;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_nscdd");

/// A valid scene: a disk resting on a fixed floor.
const BASE: &str = r#"[time]
step = 1e-3
steps = 10

[[materials]]
name = "grain"
density = 2600.0

[[laws]]
materials = ["grain", "grain"]
friction = 0.3

[[bodies]]
name = "floor"
shape = "halfplane"
material = "grain"
position = [0.0, 0.0]
fixed = true

[[bodies]]
name = "ball"
shape = "disk"
material = "grain"
position = [0.0, 0.1]
radius = 0.1
"#;

/// A fresh directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("nscdd-bad-input-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn nscdd(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(BIN).args(args).output().expect("the nscdd binary runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// `base` with `from` replaced by `to` (which must occur once).
fn edit(base: &str, from: &str, to: &str) -> String {
    assert_eq!(base.matches(from).count(), 1, "`{from}` must occur once in the base scene");
    base.replacen(from, to, 1)
}

/// 1-based line of the first line of `scene` that contains `marker`.
fn line_of(scene: &str, marker: &str) -> usize {
    scene
        .lines()
        .position(|l| l.contains(marker))
        .unwrap_or_else(|| panic!("`{marker}` is not in the scene"))
        + 1
}

struct Case {
    name: &'static str,
    scene: String,
    /// The key path the message must name.
    key: &'static str,
    /// A text on the line the message must name.
    marker: &'static str,
}

fn check_bad(c: &Case) {
    let dir = scratch(c.name);
    let path = dir.join(format!("{}.toml", c.name));
    std::fs::write(&path, &c.scene).expect("write scene");
    let line = line_of(&c.scene, c.marker);
    let expected = format!("{}:{}: key `{}`: ", path.display(), line, c.key);
    let out = dir.join("out");

    let check = nscdd(&["check".as_ref(), path.as_os_str()]);
    let run = nscdd(&[
        "run".as_ref(),
        path.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--quiet".as_ref(),
    ]);
    for (what, o) in [("check", &check), ("run", &run)] {
        let err = text(&o.stderr);
        println!("{} ({what}): {}", c.name, err.trim_end());
        assert_eq!(o.status.code(), Some(2), "{}: `{what}` must exit with 2; stderr: {err}", c.name);
        assert!(!err.contains("panicked"), "{}: `{what}` panicked: {err}", c.name);
        assert_eq!(
            err.trim_end().lines().count(),
            1,
            "{}: `{what}` must print one message: {err}",
            c.name
        );
        assert!(
            err.contains(&expected),
            "{}: `{what}` stderr must contain `{expected}`, got: {err}",
            c.name
        );
        assert!(
            text(&o.stdout).trim().is_empty(),
            "{}: `{what}` printed on stdout: {}",
            c.name,
            text(&o.stdout)
        );
    }
    let entries: Vec<String> = std::fs::read_dir(&out)
        .expect("DIR exists")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(entries, ["error.txt"], "{}: DIR must hold only error.txt", c.name);
    let saved = std::fs::read_to_string(out.join("error.txt")).expect("error.txt");
    assert!(
        saved.contains(&expected),
        "{}: error.txt must hold the message, got: {saved}",
        c.name
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_base_scene_is_valid() {
    let dir = scratch("valid");
    let path = dir.join("valid.toml");
    std::fs::write(&path, BASE).expect("write scene");
    let o = nscdd(&["check".as_ref(), path.as_os_str()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn syntax_error() {
    let scene = edit(BASE, "name = \"grain\"", "name = \"grain\" x");
    check_bad(&Case {
        name: "syntax",
        scene,
        key: "materials[0].name",
        marker: "\"grain\" x",
    });
}

#[test]
fn unknown_top_level_key() {
    let scene = format!("bogus = 1\n{BASE}");
    check_bad(&Case {
        name: "unknown_top",
        scene,
        key: "bogus",
        marker: "bogus",
    });
}

#[test]
fn unknown_key_in_a_section() {
    let scene = edit(BASE, "steps = 10", "steps = 10\nsubsteps = 3");
    check_bad(&Case {
        name: "unknown_time",
        scene,
        key: "time.substeps",
        marker: "substeps",
    });
}

#[test]
fn unknown_key_in_a_body() {
    let scene = edit(BASE, "radius = 0.1", "radius = 0.1\ncolour = \"red\"");
    check_bad(&Case {
        name: "unknown_body",
        scene,
        key: "bodies[1].colour",
        marker: "colour",
    });
}

#[test]
fn negative_radius() {
    let scene = edit(BASE, "radius = 0.1", "radius = -0.1");
    check_bad(&Case {
        name: "negative_radius",
        scene,
        key: "bodies[1].radius",
        marker: "radius",
    });
}

#[test]
fn negative_generated_radius() {
    let scene = format!(
        "{BASE}\n[[generate]]\nkind = \"square_lattice\"\nmaterial = \"grain\"\nnx = 2\nny = 2\nradius = -0.01\norigin = [1.0, 1.0]\n"
    );
    check_bad(&Case {
        name: "negative_generated_radius",
        scene,
        key: "generate[0].radius",
        marker: "radius = -0.01",
    });
}

#[test]
fn negative_density() {
    let scene = edit(BASE, "density = 2600.0", "density = -2600.0");
    check_bad(&Case {
        name: "negative_density",
        scene,
        key: "materials[0].density",
        marker: "density",
    });
}

#[test]
fn negative_time_step() {
    let scene = edit(BASE, "step = 1e-3", "step = -1e-3");
    check_bad(&Case {
        name: "negative_step",
        scene,
        key: "time.step",
        marker: "step = -1e-3",
    });
}

#[test]
fn zero_time_step() {
    let scene = edit(BASE, "step = 1e-3", "step = 0.0");
    check_bad(&Case {
        name: "zero_step",
        scene,
        key: "time.step",
        marker: "step = 0.0",
    });
}

#[test]
fn negative_friction() {
    let scene = edit(BASE, "friction = 0.3", "friction = -0.3");
    check_bad(&Case {
        name: "negative_friction",
        scene,
        key: "laws[0].friction",
        marker: "friction",
    });
}

#[test]
fn overlapping_bodies() {
    // the ball sinks 0.05 m into the floor; the tolerance is 0.05 × 0.1 m
    let scene = edit(BASE, "position = [0.0, 0.1]", "position = [0.0, 0.05]");
    check_bad(&Case {
        name: "overlap",
        scene,
        key: "bodies[1].position",
        marker: "position = [0.0, 0.05]",
    });
}

#[test]
fn contacting_materials_without_a_law() {
    let scene = edit(
        BASE,
        "[[bodies]]\nname = \"ball\"\nshape = \"disk\"\nmaterial = \"grain\"",
        "[[bodies]]\nname = \"ball\"\nshape = \"disk\"\nmaterial = \"steel\"",
    );
    let scene = edit(&scene, "[[laws]]", "[[materials]]\nname = \"steel\"\ndensity = 7800.0\n\n[[laws]]");
    // the message names the first body of the pair's first material (the floor)
    check_bad(&Case {
        name: "no_law",
        scene: scene.clone(),
        key: "bodies[0].material",
        marker: "material = \"grain\"",
    });
    let err = {
        let dir = scratch("no_law_msg");
        let p = dir.join("s.toml");
        std::fs::write(&p, &scene).expect("write");
        let o = nscdd(&["check".as_ref(), p.as_os_str()]);
        let _ = std::fs::remove_dir_all(&dir);
        text(&o.stderr)
    };
    assert!(err.contains("no law for the material pair (`grain`, `steel`)"), "{err}");
}

#[test]
fn driven_dof_that_does_not_exist() {
    let scene = edit(BASE, "radius = 0.1", "radius = 0.1\ndrive.z = { velocity = 1.0 }");
    check_bad(&Case {
        name: "drive_z",
        scene,
        key: "bodies[1].drive.z",
        marker: "drive.z",
    });
}

#[test]
fn unknown_shape() {
    let scene = edit(BASE, "shape = \"disk\"", "shape = \"sphere\"");
    check_bad(&Case {
        name: "unknown_shape",
        scene,
        key: "bodies[1].shape",
        marker: "sphere",
    });
}

#[test]
fn wrong_value_type() {
    let scene = edit(BASE, "position = [0.0, 0.1]", "position = [0.0, \"high\"]");
    check_bad(&Case {
        name: "wrong_type",
        scene,
        key: "bodies[1].position[1]",
        marker: "\"high\"",
    });
}

#[test]
fn missing_file() {
    let dir = scratch("missing");
    let path = dir.join("nowhere.toml");
    let o = nscdd(&["check".as_ref(), path.as_os_str()]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&path.display().to_string()) && err.contains("cannot read the file") && !err.contains("panicked"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A light disk pushed by an imposed force that jumps to 1e308 N at t = 5.05 ms:
/// h f / m = 1e-3 × 1e308 / 3.1e-9 overflows, so step 6 gives an infinite velocity.
const DIVERGING: &str = r#"[time]
step = 1e-3
steps = 20

[[materials]]
name = "grain"
density = 1e-3

[[laws]]
materials = ["grain", "grain"]
friction = 0.3

[[bodies]]
shape = "halfplane"
material = "grain"
position = [0.0, 0.0]
fixed = true

[[bodies]]
name = "rocket"
shape = "disk"
material = "grain"
position = [0.0, 0.001]
radius = 1e-3
drive.x = { force = { table = [[0.0, 0.0], [0.005, 0.0], [0.0051, 1e308]] } }
"#;

#[test]
fn a_diverging_run_stops_and_keeps_its_history() {
    let dir = scratch("diverge");
    let path = dir.join("diverge.toml");
    std::fs::write(&path, DIVERGING).expect("write scene");
    let out = dir.join("out");
    let o = nscdd(&[
        "run".as_ref(),
        path.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--quiet".as_ref(),
    ]);
    let err = text(&o.stderr);
    println!("diverge: {}", err.trim_end());
    assert_eq!(o.status.code(), Some(1), "a diverging run exits with 1: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("step 6") && err.contains("body 1") && err.contains("rocket"),
        "the message must name the step and the body: {err}"
    );
    assert!(err.contains("non-finite"), "{err}");
    let hist = std::fs::read_to_string(out.join("history.csv")).expect("history.csv is kept");
    let rows: Vec<&str> = hist.lines().collect();
    assert!(rows[0].starts_with("step,time,"), "header: {}", rows[0]);
    assert_eq!(rows.len(), 1 + 5, "the 5 steps before the divergence are kept:\n{hist}");
    for (k, r) in rows[1..].iter().enumerate() {
        assert!(r.starts_with(&format!("{},", k + 1)), "row {k}: {r}");
        assert!(!r.contains("NaN") && !r.contains("inf"), "finite rows before the divergence: {r}");
    }
    assert!(!out.join("final.json").exists(), "no final state for a diverged run");
    let _ = std::fs::remove_dir_all(&dir);
}

// ---- [decomposition] and the NSCDD flags (issue 3) ----

/// BASE with a `[decomposition]` section holding `body`.
fn with_decomposition(body: &str) -> String {
    format!("{BASE}\n[decomposition]\n{body}\n")
}

#[test]
fn zero_subdomains_in_the_scene() {
    check_bad(&Case {
        name: "dd_zero_nx",
        scene: with_decomposition("nx = 0\nny = 1"),
        key: "decomposition.nx",
        marker: "nx = 0",
    });
}

#[test]
fn negative_subdomains_in_the_scene() {
    check_bad(&Case {
        name: "dd_negative_ny",
        scene: with_decomposition("nx = 1\nny = -2"),
        key: "decomposition.ny",
        marker: "ny = -2",
    });
}

#[test]
fn unknown_scheme_in_the_scene() {
    check_bad(&Case {
        name: "dd_scheme",
        scene: with_decomposition("nx = 1\nny = 1\nscheme = \"ring\""),
        key: "decomposition.scheme",
        marker: "ring",
    });
}

#[test]
fn unknown_key_in_the_decomposition() {
    check_bad(&Case {
        name: "dd_unknown",
        scene: with_decomposition("nx = 1\nnz = 2"),
        key: "decomposition.nz",
        marker: "nz = 2",
    });
}

#[test]
fn zero_repartition_period() {
    check_bad(&Case {
        name: "dd_repartition",
        scene: with_decomposition("nx = 1\nrepartition_every = 0"),
        key: "decomposition.repartition_every",
        marker: "repartition_every",
    });
}

#[test]
fn more_subdomains_than_the_sample_holds_in_the_scene() {
    // one movable body: at most one subdomain
    check_bad(&Case {
        name: "dd_too_many",
        scene: with_decomposition("nx = 2\nny = 2"),
        key: "decomposition.nx",
        marker: "nx = 2",
    });
}

/// `nscdd run BASE --out DIR ARGS...` must exit with 2, print one line naming `flag`
/// and leave only error.txt in DIR.
fn check_bad_flags(name: &str, scene: &str, args: &[&str], flag: &str) {
    let dir = scratch(name);
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).expect("write scene");
    let out = dir.join("out");
    let mut a: Vec<&std::ffi::OsStr> = vec![
        "run".as_ref(),
        path.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--quiet".as_ref(),
    ];
    a.extend(args.iter().map(std::ffi::OsStr::new));
    let o = nscdd(&a);
    let err = text(&o.stderr);
    println!("{name}: {}", err.trim_end());
    assert_eq!(o.status.code(), Some(2), "{name}: exit 2 expected; stderr: {err}");
    assert!(!err.contains("panicked"), "{name}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{name}: one message: {err}");
    assert!(
        err.starts_with("error: ") && err.contains(flag),
        "{name}: the message must name `{flag}`: {err}"
    );
    let entries: Vec<String> = std::fs::read_dir(&out)
        .expect("DIR exists")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(entries, ["error.txt"], "{name}: DIR must hold only error.txt");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn malformed_subdomains_flag() {
    for (k, v) in ["2x", "0x2", "-1x2", "2x0", "x2", "2", "2x2x2", "ax2", "1.5x2", ""]
        .iter()
        .enumerate()
    {
        check_bad_flags(&format!("flag_subdomains_{k}"), BASE, &["--subdomains", v], "--subdomains");
    }
}

#[test]
fn more_subdomains_than_the_sample_holds_on_the_command_line() {
    check_bad_flags("flag_too_many", BASE, &["--subdomains", "2x1"], "--subdomains");
}

#[test]
fn unknown_scheme_flag() {
    check_bad_flags("flag_scheme", BASE, &["--subdomains", "1x1", "--scheme", "ring"], "--scheme");
}

#[test]
fn bad_threads_flag() {
    for (k, v) in ["0", "-2", "two"].iter().enumerate() {
        check_bad_flags(
            &format!("flag_threads_{k}"),
            BASE,
            &["--subdomains", "1x1", "--threads", v],
            "--threads",
        );
    }
}

#[test]
fn scheme_flag_without_a_decomposition() {
    check_bad_flags("flag_scheme_alone", BASE, &["--scheme", "centralized"], "--scheme");
}

#[test]
fn subdomains_flag_runs_nscdd() {
    let dir = scratch("flag_ok");
    let path = dir.join("scene.toml");
    // the flags override the scene's section
    std::fs::write(&path, with_decomposition("nx = 1\nny = 1\nscheme = \"decentralized\"")).expect("write scene");
    let out = dir.join("out");
    let o = nscdd(&[
        "run".as_ref(),
        path.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--quiet".as_ref(),
        "--subdomains".as_ref(),
        "1x1".as_ref(),
        "--scheme".as_ref(),
        "centralized".as_ref(),
        "--threads".as_ref(),
        "2".as_ref(),
    ]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("1x1 subdomains") && err.contains("Centralized"), "{err}");
    let hist = std::fs::read_to_string(out.join("history.csv")).expect("history.csv");
    let head = hist.lines().next().unwrap();
    assert!(
        head.ends_with(",nscdd_iterations,egluing,egluing_rel,interface_bodies,links,migrations,prevailing,subdomains"),
        "{head}"
    );
    assert_eq!(hist.lines().count(), 11);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn missing_restart_file() {
    check_bad_flags(
        "flag_restart_missing",
        BASE,
        &["--restart", "/nonexistent/final.json"],
        "/nonexistent/final.json",
    );
}

#[test]
fn restart_continues_and_never_overwrites_its_own_run() {
    let dir = scratch("restart");
    let path = dir.join("scene.toml");
    std::fs::write(&path, BASE).expect("write scene");
    let first = dir.join("first");
    let run = |out: &PathBuf, extra: &[&std::ffi::OsStr]| {
        let mut a: Vec<&std::ffi::OsStr> = vec![
            "run".as_ref(),
            path.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
            "--quiet".as_ref(),
        ];
        a.extend_from_slice(extra);
        nscdd(&a)
    };
    // a first run of 10 steps; the scene then asks for 20
    assert_eq!(run(&first, &[]).status.code(), Some(0));
    std::fs::write(&path, edit(BASE, "steps = 10", "steps = 20")).expect("write scene");
    let state = first.join("final.json");
    let before = std::fs::read_to_string(first.join("history.csv")).unwrap();
    let o = run(&first, &["--restart".as_ref(), state.as_os_str()]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.starts_with("error: --out:") && err.contains("restart file"), "{err}");
    assert_eq!(std::fs::read_to_string(first.join("history.csv")).unwrap(), before, "nothing lost");
    let second = dir.join("second");
    let o = run(&second, &["--restart".as_ref(), state.as_os_str()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let hist = std::fs::read_to_string(second.join("history.csv")).unwrap();
    assert_eq!(hist.lines().count(), 11, "steps 11 to 20");
    assert!(hist.lines().nth(1).unwrap().starts_with("11,"));
    let _ = std::fs::remove_dir_all(&dir);
}
