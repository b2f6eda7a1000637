//! The `nscdd` binary on malformed scenes and on a diverging run.
//!
//! Every malformed scene must give exit code 2 and one message on stderr,
//! `error: FILE:LINE: key `KEY`: ...`, naming the file, the line of the offending key
//! and the key's full path, without a panic; `nscdd run SCENE --out DIR` must then
//! leave nothing in DIR but `error.txt` (holding the same message). A run that
//! diverges must stop with exit code 1, name the step and the body, and keep the
//! `history.csv` written so far.

mod common;

use common::*;

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

/// A step longer than the duration (the scene would run no step) and a step so
/// short that the run would take more than 10¹² steps (it used to run 0 steps, and
/// `as u64` saturated to 1.8e19 steps): refused, naming time.duration.
#[test]
fn a_duration_of_no_step_or_of_too_many() {
    for (name, step) in [("no_step", "1e308"), ("too_many", "1e-300")] {
        let scene = edit(BASE, "steps = 10", "duration = 0.2").replace("step = 1e-3", &format!("step = {step}"));
        check_bad(&Case {
            name,
            scene,
            key: "time.duration",
            marker: "duration",
        });
    }
    let scene = edit(BASE, "steps = 10", "steps = 9000000000000000000");
    check_bad(&Case {
        name: "steps_too_many",
        scene,
        key: "time.steps",
        marker: "steps = 9",
    });
}

// ---- [solver] method and solve-fc --method (issue 19) ----

/// A setting the chosen method cannot use is refused naming its key and line; an
/// unknown method names `solver.method`.
#[test]
fn solver_settings_a_method_cannot_use() {
    for (name, solver, key, marker) in [
        ("method_unknown", "method = \"cg\"", "solver.method", "method"),
        (
            "method_ordering",
            "method = \"newton\"\nordering = \"shuffled\"",
            "solver.ordering",
            "ordering",
        ),
        (
            "method_relaxation",
            "method = \"newton\"\nrelaxation = 0.5",
            "solver.relaxation",
            "relaxation",
        ),
        ("relaxation_too_large", "relaxation = 2.0", "solver.relaxation", "relaxation"),
        (
            "method_scrambled",
            "method = \"anderson\"\nordering = \"scrambled\"",
            "solver.ordering",
            "ordering",
        ),
        (
            "sort_direction_unsorted",
            "sort_direction = [0.0, 1.0]",
            "solver.sort_direction",
            "sort_direction",
        ),
        (
            "sort_direction_zero",
            "ordering = \"sorted\"\nsort_direction = [0.0, 0.0]",
            "solver.sort_direction",
            "sort_direction",
        ),
    ] {
        let scene = edit(BASE, "[[materials]]", &format!("[solver]\n{solver}\n\n[[materials]]"));
        check_bad(&Case { name, scene, key, marker });
    }
}

/// `solve-fc --method`: every method solves a two-contact problem, NLGS and
/// Anderson over-relaxed too; an unknown method, `--repeat 0`, a relaxation out of
/// (0, 2) or one given to Newton is an input error (exit 2).
#[test]
fn solve_fc_methods() {
    let dir = scratch("solve_fc_methods");
    let p = dir.join("two.json");
    let json = r#"{"dim": 2, "nc": 2, "W": {"n": 4, "rows": [0, 1, 2, 3, 0, 2], "cols": [0, 1, 2, 3, 2, 0],
        "vals": [2.0, 2.0, 2.0, 2.0, 1.0, 1.0]}, "q": [-1.0, 0.0, -1.0, 0.0], "mu": [0.5, 0.5]}"#;
    std::fs::write(&p, json).unwrap();
    for (m, omega) in [
        ("nlgs", "1"),
        ("anderson", "1"),
        ("newton", "1"),
        ("nlgs", "1.3"),
        ("anderson", "1.3"),
    ] {
        let o = nscdd(&[
            "solve-fc".as_ref(),
            p.as_os_str(),
            "--method".as_ref(),
            m.as_ref(),
            "--repeat".as_ref(),
            "3".as_ref(),
            "--relaxation".as_ref(),
            omega.as_ref(),
        ]);
        let out = text(&o.stdout);
        assert!(
            o.status.success() && out.contains("\"converged\":true"),
            "{m}: {out} {}",
            text(&o.stderr)
        );
    }
    for bad in [
        vec!["--method", "cg"],
        vec!["--repeat", "0"],
        vec!["--relaxation", "2"],
        vec!["--relaxation", "1.2", "--method", "newton"],
    ] {
        let mut args: Vec<&std::ffi::OsStr> = vec!["solve-fc".as_ref(), p.as_os_str()];
        args.extend(bad.iter().map(|a: &&str| -> &std::ffi::OsStr { a.as_ref() }));
        let o = nscdd(&args);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", text(&o.stderr));
        assert!(text(&o.stderr).contains(bad[0]), "{bad:?}: {}", text(&o.stderr));
    }
    let _ = std::fs::remove_dir_all(&dir);
}
