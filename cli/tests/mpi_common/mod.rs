//! What the MPI tests share (`cli/tests/mpi.rs`, `mpi_faults.rs`, `mpi_signals.rs`): the
//! program, the time limit, scratch directories, the `mpirun` command a root
//! container needs, and the 2D pile they run.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

pub const BIN: &str = env!("CARGO_BIN_EXE_nscdd");

/// No test may take longer: a failure must never hang the ranks.
pub const LIMIT: Duration = Duration::from_secs(120);

pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("nscdd-mpi-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch dir");
    d
}

pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

pub fn args(scene: &Path, out: &Path, extra: &[&str]) -> Vec<String> {
    let mut v = vec![
        "run".to_string(),
        scene.display().to_string(),
        "--out".into(),
        out.display().to_string(),
        "--quiet".into(),
    ];
    v.extend(extra.iter().map(|s| s.to_string()));
    v
}

/// A session directory of its own for each `mpirun`: OpenMPI's default one
/// (`/tmp/ompi.HOST.UID`) is made by every job, and two jobs started at the same
/// moment by parallel tests can fail on it (`mkdir … File exists`).
pub fn session_dir() -> PathBuf {
    static STALE: std::sync::Once = std::sync::Once::new();
    STALE.call_once(remove_stale_session_dirs);
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let d = std::env::temp_dir().join(format!("nscdd-ompi-{}-{k}", std::process::id()));
    std::fs::create_dir_all(&d).expect("session dir");
    d
}

/// The session directories of test processes that have ended (OpenMPI leaves them
/// behind; a process is gone when `/proc` has no entry for its id): removed once
/// per test process. Elsewhere than on Linux nothing is removed.
fn remove_stale_session_dirs() {
    let (Ok(entries), true) = (std::fs::read_dir(std::env::temp_dir()), Path::new("/proc/self").exists()) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(pid) = name.strip_prefix("nscdd-ompi-").and_then(|r| r.split('-').next()) else {
            continue;
        };
        if pid.parse::<u32>().is_ok() && !Path::new("/proc").join(pid).exists() {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

/// `mpirun` with the settings a root container needs; `apps` are the programs of an
/// MPMD launch (`-n k nscdd ARGS` each), all run as one job.
pub fn mpirun_command(apps: &[(u32, Vec<String>)]) -> Command {
    let mut c = Command::new("mpirun");
    c.env("OMPI_MCA_orte_tmpdir_base", session_dir())
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
        // shared memory between the ranks of one machine, no network probing
        .env("OMPI_MCA_btl", "self,vader")
        // containers often forbid the cross-memory attach of large messages
        .env("OMPI_MCA_btl_vader_single_copy_mechanism", "none")
        .arg("--oversubscribe");
    for (i, (n, args)) in apps.iter().enumerate() {
        if i > 0 {
            c.arg(":");
        }
        c.arg("-n").arg(n.to_string()).arg(BIN).args(args);
    }
    c
}

/// 64 disks of a triangular lattice, 16 wide, on a floor between two walls: a pile
/// wide enough for four strips whose interface bodies are shared by adjacent strips
/// only.
pub const PILE2D: &str = r#"
[time]
step = 1e-3
steps = 15
[solver]
tolerance = 1e-5
norm = "QM/16"
max_sweeps = 3000
check_every = 5
[output]
every = 5
[[materials]]
name = "m"
density = 1000.0
[[laws]]
materials = ["m", "m"]
friction = 0.3
[[bodies]]
name = "floor"
shape = "wall"
material = "m"
position = [0.16, -0.005]
length = 0.4
thickness = 0.01
fixed = true
[[bodies]]
shape = "wall"
material = "m"
position = [-0.005, 0.05]
rotation = 1.5707963267948966
length = 0.2
thickness = 0.01
fixed = true
[[bodies]]
shape = "wall"
material = "m"
position = [0.335, 0.05]
rotation = 1.5707963267948966
length = 0.2
thickness = 0.01
fixed = true
[[generate]]
kind = "triangular_lattice"
material = "m"
nx = 16
ny = 4
radius = 0.01
origin = [0.01, 0.01]
"#;

/// `NumberOf…="n"` attributes of a VTK file's pieces, summed.
pub fn vtk_count(path: &Path, what: &str) -> usize {
    let t = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let key = format!("{what}=\"");
    t.match_indices(&key)
        .map(|(i, _)| {
            let rest = &t[i + key.len()..];
            rest[..rest.find('"').expect("closing quote")].parse::<usize>().expect("a count")
        })
        .sum()
}

pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write scene");
    p
}

/// final.json, with its NSCDD solver state (gathered from every rank on rank 0).
pub fn final_json(out: &Path) -> String {
    std::fs::read_to_string(out.join("final.json")).unwrap_or_else(|e| panic!("{}: {e}", out.display()))
}

/// Each rank's entry of the run's `ranks.json` (in rank order).
pub fn per_rank(out: &Path) -> Vec<serde_json::Value> {
    let t = std::fs::read_to_string(out.join("ranks.json")).expect("ranks.json");
    let v: serde_json::Value = serde_json::from_str(&t).expect("ranks.json is JSON");
    v["per_rank"].as_array().expect("per_rank").clone()
}

/// Each rank's count `key` in the run's `ranks.json` (in rank order).
pub fn per_rank_count(out: &Path, key: &str) -> Vec<u64> {
    per_rank(out)
        .iter()
        .map(|r| r[key].as_u64().unwrap_or_else(|| panic!("{key}: {r}")))
        .collect()
}

/// `text` re-partitioned every `k` steps: in between, each rank holds only its
/// subdomains' contacts (`dd::local`).
pub fn every(text: &str, k: u32) -> String {
    format!("{text}\n[decomposition]\nrepartition_every = {k}\n")
}

/// The 4 ranks' pieces of `out` hold the bodies and contacts of `one`'s frames.
pub fn pieces_add_up(one: &Path, out: &Path) {
    pieces_add_up_in(one, out, 4, 4);
    let pvd = std::fs::read_to_string(out.join("bodies.pvd")).expect("bodies.pvd");
    assert!(pvd.contains("vtk/bodies_000003.pvtp"), "{pvd}");
}

/// The pieces of `ranks` ranks in `out` hold the bodies and contacts of `one`'s
/// first `frames` frames, each body and contact once.
pub fn pieces_add_up_in(one: &Path, out: &Path, frames: u32, ranks: u32) {
    for frame in 0..frames {
        for (name, what) in [
            ("bodies", "NumberOfPoints"),
            ("contacts", "NumberOfLines"),
            ("points", "NumberOfVerts"),
        ] {
            let stem = format!("{name}_{frame:06}");
            let p = std::fs::read_to_string(out.join("vtk").join(format!("{stem}.pvtp"))).expect("the .pvtp");
            let mut sum = 0;
            for r in 0..ranks {
                let piece = format!("{stem}_{r}.vtp");
                assert!(p.contains(&format!("Source=\"{piece}\"")), "{stem}.pvtp names {piece}");
                let path = out.join("vtk").join(&piece);
                // empty pieces too carry their counts (VTK's readers refuse them otherwise)
                let t = std::fs::read_to_string(&path).expect("a piece");
                assert!(t.contains("NumberOfPoints=\""), "{piece}: no NumberOfPoints");
                sum += vtk_count(&path, what);
            }
            let whole = vtk_count(&one.join("vtk").join(format!("{stem}.vtp")), what);
            assert_eq!(sum, whole, "{stem}: {what} of the pieces");
            if name == "contacts" && frame > 0 {
                assert!(whole > 0);
            }
        }
        assert!(!out.join("vtk").join(format!("bodies_{frame:06}.vtp")).exists());
    }
}

/// Runs a command to its end or kills it after [`LIMIT`] (then fails the test).
pub fn run_limited(mut c: Command) -> Output {
    let t0 = Instant::now();
    let mut child = c.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("start the command");
    loop {
        if child.try_wait().expect("wait").is_some() {
            break;
        }
        if t0.elapsed() > LIMIT {
            let _ = child.kill();
            let o = child.wait_with_output().expect("output");
            panic!("still running after {LIMIT:?} (a hang): {}", String::from_utf8_lossy(&o.stderr));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("output")
}

/// `mpirun` of `apps` ([`mpirun_command`]), run to its end within [`LIMIT`].
pub fn mpirun(apps: &[(u32, Vec<String>)]) -> Output {
    run_limited(mpirun_command(apps))
}

pub fn nscdd(args: &[String]) -> Output {
    let mut c = Command::new(BIN);
    c.args(args);
    run_limited(c)
}

/// A 5 × 5 × 3 lattice of spheres, jostled by a tilted gravity, settling on a floor
/// plane between box walls.
pub const PILE3D: &str = r#"
dimension = 3
gravity = [1.0, 0.5, -9.81]
[time]
step = 1e-3
steps = 10
[solver]
tolerance = 1e-4
norm = "QM/16"
max_sweeps = 3000
check_every = 5
[output]
every = 5
[[materials]]
name = "m"
density = 2500.0
[[laws]]
materials = ["m", "m"]
friction = 0.4
[[bodies]]
name = "floor"
shape = "plane"
material = "m"
position = [0.0, 0.0, 0.0]
fixed = true
[[bodies]]
shape = "box"
material = "m"
position = [0.101, 0.05, 0.05]
half_extents = [0.001, 0.1, 0.1]
fixed = true
[[generate]]
kind = "sphere_lattice"
material = "m"
nx = 5
ny = 5
nz = 3
radius = 0.01
origin = [0.01, 0.01, 0.01]
"#;

/// Asserts that a run succeeded, printing its outputs otherwise.
pub fn ok(o: &Output, what: &str) {
    assert!(
        o.status.success(),
        "{what} failed ({:?}):\n{}\n{}",
        o.status.code(),
        text(&o.stdout),
        text(&o.stderr)
    );
}
