//! The `nscdd` binary on malformed decompositions (the scene's `[decomposition]`
//! and the `--subdomains`, `--scheme`, `--threads` flags) and restarts: exit code
//! 2 and one message naming the file, line and key, or the flag; a valid
//! `--subdomains` runs NSCDD; a restart continues without overwriting its own run.

mod common;

use common::*;
use std::path::PathBuf;

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
        head.ends_with(
            ",nscdd_iterations,egluing,egluing_rel,interface_bodies,links,migrations,prevailing,subdomains,repartitioned,imbalance"
        ),
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

/// A scene with deformable bodies refuses a bad flag with exit 2 and a message
/// naming it, and a restart from a state of another scene (a rigid one); its
/// export-fc writes the coupled step's problem (the deformable contacts after the
/// world's), which solve-fc solves.
#[cfg(feature = "fem")]
#[test]
fn deformable_scenes_refuse_what_they_cannot_run() {
    let dir = common::scratch("fe_refusals");
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenes/foundation.toml");
    let scene3 = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenes/foundation3d.toml");
    let rigid = dir.join("rigid.toml");
    let text = "[time]\nstep = 1e-3\nsteps = 2\n[[materials]]\nname = \"m\"\ndensity = 1000.0\n[[bodies]]\nshape = \"disk\"\nmaterial = \"m\"\nradius = 0.1\nposition = [0.0, 0.0]\n";
    std::fs::write(&rigid, text).unwrap();
    let out = dir.join("out");
    // a rigid scene's state
    let state = dir.join("rigid");
    let o = std::process::Command::new(common::BIN)
        .arg("run")
        .arg(&rigid)
        .args(["--quiet", "--out"])
        .arg(&state)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let state = state.join("final.json");
    let cases: [(&str, Vec<&str>, &str); 2] = [
        (scene3, vec!["run", scene3, "--threads", "0"], "--threads"),
        (
            scene,
            vec!["run", scene, "--restart", state.to_str().unwrap()],
            "the scene that wrote it",
        ),
    ];
    for (_, args, said) in cases {
        let mut cmd = std::process::Command::new(common::BIN);
        cmd.args(&args).arg("--out").arg(&out);
        if args[0] == "run" {
            cmd.arg("--quiet");
        }
        let o = cmd.output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(said), "{args:?}: {err}");
        assert!(!out.join("history.csv").exists(), "{args:?} ran");
    }
    let fc = dir.join("coupled.json");
    let o = std::process::Command::new(common::BIN)
        .args(["export-fc", scene, "--steps", "20", "--out"])
        .arg(&fc)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let o = std::process::Command::new(common::BIN)
        .arg("solve-fc")
        .arg(&fc)
        .args(["--tol", "1e-8", "--max-sweeps", "100000"])
        .output()
        .unwrap();
    let sol = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && sol.contains("\"converged\":true"),
        "{sol} {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// A deformable scene run by model on 2 subdomains, stopped at step 20 and restarted
/// from its final.json (the deformable bodies' and NSCDD's states in it) to step
/// 40: bitwise the final state of the uninterrupted run; a checkpoint too.
#[cfg(feature = "fem")]
#[test]
fn deformable_scenes_restart_bitwise() {
    let dir = common::scratch("fe_restart");
    let src = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenes/foundation.toml")).unwrap();
    let whole = dir.join("whole.toml");
    std::fs::write(
        &whole,
        src.replace("duration = 0.5", "steps = 40")
            .replace("[output]\n", "[output]\ncheckpoint_every = 20\nvtk = false\n"),
    )
    .unwrap();
    let first = dir.join("first.toml");
    std::fs::write(
        &first,
        src.replace("duration = 0.5", "steps = 20")
            .replace("[output]\n", "[output]\nvtk = false\n"),
    )
    .unwrap();
    let run = |scene: &std::path::Path, name: &str, flags: &[&str]| {
        let out = dir.join(name);
        let o = std::process::Command::new(common::BIN)
            .arg("run")
            .arg(scene)
            .args(["--quiet", "--out"])
            .arg(&out)
            .args(flags)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{flags:?}: {}", String::from_utf8_lossy(&o.stderr));
        out
    };
    let a = run(&whole, "whole", &[]);
    let b = run(&first, "first", &[]);
    let from = b.join("final.json");
    let c = run(&whole, "second", &["--restart", from.to_str().unwrap()]);
    let fin = |d: &std::path::Path| std::fs::read_to_string(d.join("final.json")).unwrap();
    assert!(fin(&a) == fin(&c), "the restarted run ends elsewhere");
    let ck = std::fs::read_to_string(a.join("checkpoint.json")).unwrap();
    assert!(
        ck.contains("\"deformable\"") && ck.contains("\"nscdd\""),
        "the checkpoint holds the family's and NSCDD's states"
    );
}

/// A 2D scene with deformable bodies takes the NSCDD flags: `--threads 2` gives
/// bitwise the final state of one thread, `--subdomains` and `--scheme` run.
#[cfg(feature = "fem")]
#[test]
fn deformable_scenes_take_the_nscdd_flags() {
    let dir = common::scratch("fe_flags");
    let src = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenes/foundation.toml")).unwrap();
    let scene = dir.join("foundation.toml");
    std::fs::write(&scene, src.replace("duration = 0.5", "steps = 40")).unwrap();
    let run = |name: &str, flags: &[&str]| {
        let out = dir.join(name);
        let o = std::process::Command::new(common::BIN)
            .args(["run"])
            .arg(&scene)
            .args(["--quiet", "--out"])
            .arg(&out)
            .args(flags)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{flags:?}: {}", String::from_utf8_lossy(&o.stderr));
        std::fs::read_to_string(out.join("final.json")).unwrap()
    };
    let one = run("t1", &["--threads", "1"]);
    assert_eq!(one, run("t2", &["--threads", "2"]));
    run("grid", &["--subdomains", "2x2", "--scheme", "centralized"]);
}

/// A decomposed rigid run (2 × 2 subdomains) stopped at step 15 and restarted from
/// its final.json (with NSCDD's state: F_Γ, grid, kept owners) to step 30, with 2
/// threads: bitwise the uninterrupted run's final state.
#[test]
fn decomposed_restart_continues_bitwise() {
    let dir = scratch("dd_restart");
    let pile = format!(
        "{}\n[[generate]]\nkind = \"square_lattice\"\nmaterial = \"grain\"\nradius = 0.01\norigin = [0.2, 0.01]\nnx = 10\nny = 6\nspacing = 0.02\n[decomposition]\nnx = 2\nny = 2\n[output]\nvtk = false\n",
        BASE.replace("steps = 10", "steps = 30")
    );
    let whole = dir.join("whole.toml");
    std::fs::write(&whole, &pile).unwrap();
    let first = dir.join("first.toml");
    std::fs::write(&first, pile.replace("steps = 30", "steps = 15")).unwrap();
    let run = |scene: &PathBuf, out: &str, extra: &[&str]| {
        let out = dir.join(out);
        let mut a: Vec<&std::ffi::OsStr> = vec![
            "run".as_ref(),
            scene.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
            "--quiet".as_ref(),
        ];
        a.extend(extra.iter().map(|s| std::ffi::OsStr::new(*s)));
        let o = nscdd(&a);
        assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
        std::fs::read_to_string(out.join("final.json")).unwrap()
    };
    let a = run(&whole, "whole", &[]);
    assert!(
        a.contains("\"nscdd\"") && a.contains("\"f_gamma\": [\n      ["),
        "the NSCDD state is saved, with F_Γ"
    );
    run(&first, "first", &[]);
    let state = dir.join("first").join("final.json");
    let b = run(&whole, "second", &["--threads", "2", "--restart", state.to_str().unwrap()]);
    assert!(a == b, "the restarted run ends elsewhere");
    // a damaged NSCDD state: exit 2, the file, line and key named
    let saved = std::fs::read_to_string(&state).unwrap();
    let bad = dir.join("bad.json");
    let restart_from = |state: &str, out: &str| {
        std::fs::write(&bad, state).unwrap();
        let out = dir.join(out);
        let o = nscdd(&[
            "run".as_ref(),
            whole.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
            "--restart".as_ref(),
            bad.as_os_str(),
        ]);
        (o.status.code(), text(&o.stderr))
    };
    let line = saved[..saved.find("\"f_gamma\"").unwrap()].lines().count();
    let (code, err) = restart_from(&saved.replacen("\"f_gamma\": [", "\"f_gamma\": 7, \"was\": [", 1), "bad");
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(&format!("bad.json:{line}")) && err.contains("nscdd"), "{err}");
    // a kept contact's subdomain past the grid's 4 cells: exit 2, the entry named
    let mut v: serde_json::Value = serde_json::from_str(&saved).unwrap();
    v["nscdd"]["kept"][0][1] = serde_json::json!(9);
    let (code, err) = restart_from(&serde_json::to_string_pretty(&v).unwrap(), "bad_kept");
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("kept[0]: subdomain 9 of a grid of 4 cells"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// LMGC90's quick scramble re-permutes the one-domain NLGS between check blocks;
/// NSCDD sweeps its subdomains in one order a step: refused, not ignored.
#[test]
fn scrambled_order_with_subdomains() {
    let scene = edit(BASE, "[time]", "[solver]\nordering = \"scrambled\"\n[time]");
    check_bad_flags("flag_scrambled", &scene, &["--subdomains", "1x1"], "solver.ordering");
}
