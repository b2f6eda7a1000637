//! Plugins loaded at run time (issue 18): the template's library loaded with
//! `--plugin` and by a scene's `[[plugins]]`, listed by `nscdd plugins`; libraries of
//! another interface version, corrupt, missing or not plugins refused with exit 2;
//! a plugin's panic reported as `plugin NAME: …` with the outputs kept.
//!
//! The libraries are the workspace members `templates/plugin`, `plugins/polygons`,
//! `tests/plugin_bad_abi` and `tests/plugin_panics`, built by the same cargo command as this test (the
//! README's test command builds the whole workspace): a plugin must be built with
//! the same framework build as the program that loads it. To run these tests alone,
//! build the five packages in one command first (`cargo test --release -p nscdd-cli
//! -p nscdd-plugin-template -p nscdd-polygons -p nscdd-plugin-panics -p
//! nscdd-plugin-bad-abi [--features …] --no-run`, then the same with `--test plugins`): `--test plugins` alone builds
//! no library of the plugin crates.
mod common;
use common::*;
use std::path::{Path, PathBuf};

/// The library of workspace member `name` (crate name with underscores).
fn library(name: &str) -> PathBuf {
    nscdd::plugin::built_library(name).unwrap_or_else(|| {
        panic!(
            "lib{name} is not built: run the tests of the whole workspace (cargo test --workspace --release …), which builds it with nscdd's features"
        )
    })
}

const BEAD: &str = r#"[time]
step = 1e-3
steps = 300
[[materials]]
name = "m"
density = 1000.0
[[laws]]
materials = ["m", "m"]
friction = 0.3
[[bodies]]
shape = "halfplane"
material = "m"
position = [0.0, 0.0]
fixed = true
[[bodies]]
shape = "bead"
material = "m"
radius = 0.05
position = [0.0, 0.1]
[[bodies]]
shape = "disk"
material = "m"
radius = 0.05
position = [0.0, 0.25]
"#;

fn os(s: &str) -> &std::ffi::OsStr {
    std::ffi::OsStr::new(s)
}

/// `nscdd run SCENE --out OUT --quiet [--plugin LIB]`.
fn run(scene: &Path, out: &Path, plugin: Option<&Path>) -> std::process::Output {
    let mut args = vec![os("run"), scene.as_os_str(), os("--out"), out.as_os_str(), os("--quiet")];
    if let Some(lib) = plugin {
        args.extend([os("--plugin"), lib.as_os_str()]);
    }
    nscdd(&args)
}

#[test]
fn the_template_plugin_is_listed_and_runs_a_scene() {
    let lib = library("nscdd_plugin_template");
    let o = nscdd(&[os("plugins"), os("--plugin"), lib.as_os_str()]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        out.contains("nscdd_plugin_template (loaded from") && out.contains("shape 2D bead"),
        "{out}"
    );
    assert!(
        out.contains("detector 2D bead–halfplane") && out.contains("rigid_disks (built in)"),
        "{out}"
    );
    // a scene naming the library, relative to the scene's folder
    let dir = scratch("plugin-scene");
    std::fs::copy(&lib, dir.join("libbead.so")).unwrap();
    let scene = dir.join("bead.toml");
    std::fs::write(&scene, format!("[[plugins]]\nlibrary = \"libbead.so\"\n{BEAD}")).unwrap();
    let o = run(&scene, &dir.join("out"), None);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let fin: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("out/final.json")).unwrap()).unwrap();
    // the bead rests on the floor and the disk on the bead (y = r and 3r)
    let y = |k: usize| fin["bodies"][k]["position"][1].as_f64().unwrap();
    assert!((y(1) - 0.05).abs() < 1e-3 && (y(2) - 0.15).abs() < 2e-3, "{} {}", y(1), y(2));
    // the same with --plugin instead of [[plugins]]
    std::fs::write(&scene, BEAD).unwrap();
    let o = nscdd(&[os("check"), scene.as_os_str()]);
    assert_eq!(o.status.code(), Some(2), "without the plugin `bead` is unknown");
    let o = nscdd(&[os("check"), scene.as_os_str(), os("--plugin"), lib.as_os_str()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The polygons plugin (`plugins/polygons`), the worked example: listed, and its
/// three example scenes run by `nscdd run` with their `[[plugins]]` line pointing at
/// the library built with this test; the polygons drawn as polygons in VTK.
#[test]
fn the_polygons_plugin_runs_its_example_scenes() {
    let lib = library("nscdd_polygons");
    let o = nscdd(&[os("plugins"), os("--plugin"), lib.as_os_str()]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{}", text(&o.stderr));
    for what in [
        "polygons (loaded from",
        "shape 2D polygon",
        "detector 2D polygon–polygon",
        "detector 2D polygon–disk",
        "detector 2D polygon–wall",
        "detector 2D polygon–halfplane",
        "generator 2D polygon_deposit",
        "generator 2D brick_wall_2d",
        "generator 2D arch_2d",
    ] {
        assert!(out.contains(what), "{what}: {out}");
    }
    let dir = scratch("polygon-scenes");
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../plugins/polygons/scenes");
    for (name, polys) in [("arch", 26), ("brick_wall", 53), ("deposit", 703)] {
        let given = std::fs::read_to_string(scenes.join(format!("{name}.toml"))).unwrap();
        let text_ = given
            .replace("../../../target/release/libnscdd_polygons.so", &lib.display().to_string())
            .replace("duration = 1.5", "duration = 0.02");
        assert!(text_ != given, "{name}.toml names the library as the test expects");
        let scene = dir.join(format!("{name}.toml"));
        std::fs::write(&scene, text_).unwrap();
        let out = dir.join(name);
        let o = run(&scene, &out, None);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let last = std::fs::read_dir(out.join("vtk"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with("walls_"))
            .max()
            .unwrap();
        let vtp = std::fs::read_to_string(&last).unwrap();
        assert!(vtp.contains(&format!("NumberOfPolys=\"{polys}\"")), "{name}: {}", &vtp[..200]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[track_caller]
fn refused(args: &[&std::ffi::OsStr], said: &[&str]) {
    let o = nscdd(args);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "one message: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for s in said {
        assert!(err.contains(s), "`{s}` not in: {err}");
    }
}

#[test]
fn libraries_of_another_interface_corrupt_missing_or_foreign_are_refused() {
    let dir = scratch("plugin-bad");
    let scene = dir.join("s.toml");
    std::fs::write(&scene, BEAD).unwrap();
    let bad = library("nscdd_plugin_bad_abi");
    let v = format!("interface version {}", nscdd::plugin::ABI_VERSION + 1);
    refused(
        &[os("check"), scene.as_os_str(), os("--plugin"), bad.as_os_str()],
        &["--plugin", "nscdd_plugin_bad_abi", &v, "rebuild"],
    );
    let junk = dir.join("libjunk.so");
    std::fs::write(&junk, b"\x7fELF this is not a library").unwrap();
    refused(
        &[os("check"), scene.as_os_str(), os("--plugin"), junk.as_os_str()],
        &["libjunk.so", "cannot load it"],
    );
    refused(
        &[os("plugins"), os("--plugin"), dir.join("nowhere.so").as_os_str()],
        &["nowhere.so"],
    );
    // a scene naming a missing library: its file, line and key
    std::fs::write(&scene, format!("[[plugins]]\nlibrary = \"libnone.so\"\n{BEAD}")).unwrap();
    refused(&[os("check"), scene.as_os_str()], &["s.toml:2", "plugins[0].library", "libnone.so"]);
    // a library that is not a plugin: the C library
    let foreign = [
        "/lib/x86_64-linux-gnu/libm.so.6",
        "/usr/lib/x86_64-linux-gnu/libm.so.6",
        "/lib64/libm.so.6",
    ]
    .into_iter()
    .find(|p| Path::new(p).exists());
    if let Some(f) = foreign {
        refused(&[os("plugins"), os("--plugin"), os(f)], &["not an nscdd plugin"]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_panic_in_a_plugin_is_reported_and_the_outputs_are_kept() {
    let lib = library("nscdd_plugin_panics");
    let dir = scratch("plugin-panics");
    let scene = dir.join("fragile.toml");
    let text_ = BEAD.replace("shape = \"bead\"", "shape = \"fragile\"\npanic_below = 0.02").replace(
        "[[bodies]]\nshape = \"disk\"\nmaterial = \"m\"\nradius = 0.05\nposition = [0.0, 0.25]\n",
        "",
    );
    std::fs::write(&scene, text_).unwrap();
    let out = dir.join("out");
    let o = run(&scene, &out, Some(&lib));
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("plugin nscdd_plugin_panics") && err.contains("the fragile bead broke"),
        "{err}"
    );
    assert!(!err.contains("panicked at"), "no raw panic message: {err}");
    // it fell for a while: the rows written before are kept, whole
    let hist = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(hist.lines().count() > 10 && hist.ends_with('\n'), "{hist}");
    // a plugin's law that panics when the bead lands
    let brittle = std::fs::read_to_string(&scene)
        .unwrap()
        .replace("panic_below = 0.02", "panic_below = -1.0")
        .replace("friction = 0.3", "law = \"brittle\"");
    std::fs::write(&scene, brittle).unwrap();
    let out2 = dir.join("out2");
    let o = run(&scene, &out2, Some(&lib));
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("plugin nscdd_plugin_panics") && err.contains("the brittle law broke"),
        "{err}"
    );
    assert!(std::fs::read_to_string(out2.join("history.csv")).unwrap().lines().count() > 10);
    // a plugin's body family that panics while the scene loads
    let floor_only = &BEAD[..BEAD.find("[[bodies]]\nshape = \"bead\"").unwrap()];
    std::fs::write(&scene, format!("{floor_only}[[fragile_family]]\nsize = 1\n")).unwrap();
    let o = nscdd(&[os("check"), scene.as_os_str(), os("--plugin"), lib.as_os_str()]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("plugin nscdd_plugin_panics") && err.contains("the fragile family broke loading 1 entries"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
