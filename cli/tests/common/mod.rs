//! Helpers of the `nscdd` binary's tests: a valid base scene, a scratch directory,
//! running the binary (on a scene text: [`run_scene`]), and the check that a
//! malformed scene gives exit 2 and one message naming the file, the line and the
//! key.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub const BIN: &str = env!("CARGO_BIN_EXE_nscdd");

/// A valid scene: a disk resting on a fixed floor.
pub const BASE: &str = r#"[time]
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
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("nscdd-bad-input-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

pub fn nscdd(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(BIN).args(args).output().expect("the nscdd binary runs")
}

/// Writes `scene` as `dir/name.toml`, runs it (`--quiet`, outputs in `dir/name`,
/// then `flags`), asserts exit 0 and returns the output directory.
pub fn run_scene(dir: &Path, name: &str, scene: &str, flags: &[&str]) -> PathBuf {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, scene).unwrap();
    let out = dir.join(name);
    let o = Command::new(BIN)
        .arg("run")
        .arg(&path)
        .args(["--quiet", "--out"])
        .arg(&out)
        .args(flags)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{name}: {}", text(&o.stderr));
    out
}

/// Column `name` of `out`'s history.csv, a value per step (0 where one does not
/// parse).
pub fn history_column(out: &Path, name: &str) -> Vec<f64> {
    let h = std::fs::read_to_string(out.join("history.csv")).expect("history.csv");
    let mut lines = h.lines();
    let head: Vec<&str> = lines.next().expect("header").split(',').collect();
    let k = head.iter().position(|c| *c == name).unwrap_or_else(|| panic!("no column {name}"));
    lines
        .map(|l| l.split(',').nth(k).and_then(|x| x.parse().ok()).unwrap_or(0.0))
        .collect()
}

/// Every column of `out`'s history.csv but the timings (`t_*`), the header and
/// each row.
pub fn history_physics(out: &Path) -> Vec<String> {
    let h = std::fs::read_to_string(out.join("history.csv")).expect("history.csv");
    let head: Vec<&str> = h.lines().next().expect("header").split(',').collect();
    h.lines()
        .map(|l| {
            l.split(',')
                .zip(&head)
                .filter(|(_, c)| !c.starts_with("t_"))
                .map(|(v, _)| v)
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect()
}

pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// `base` with `from` replaced by `to` (which must occur once).
pub fn edit(base: &str, from: &str, to: &str) -> String {
    assert_eq!(base.matches(from).count(), 1, "`{from}` must occur once in the base scene");
    base.replacen(from, to, 1)
}

/// 1-based line of the first line of `scene` that contains `marker`.
pub fn line_of(scene: &str, marker: &str) -> usize {
    scene
        .lines()
        .position(|l| l.contains(marker))
        .unwrap_or_else(|| panic!("`{marker}` is not in the scene"))
        + 1
}

pub struct Case {
    pub name: &'static str,
    pub scene: String,
    /// The key path the message must name.
    pub key: &'static str,
    /// A text on the line the message must name.
    pub marker: &'static str,
}

pub fn check_bad(c: &Case) {
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

/// A light disk pushed by an imposed force that jumps to 1e308 N at t = 5.05 ms:
/// h f / m = 1e-3 × 1e308 / 3.1e-9 overflows, so step 6 gives an infinite velocity.
pub const DIVERGING: &str = r#"[time]
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
