//! Scenes with continuum regions through the CLI (cargo feature `fem`): a restart
//! continues bitwise, `--threads 2` is bitwise one thread, and (feature `mpi`) the
//! ranks give the one-process result. docs/CONTINUUM.md.
#![cfg(feature = "fem")]

mod common;

/// The footing example shortened to `steps` steps (no VTK), with `extra` appended.
fn footing(steps: u32, output: &str, extra: &str) -> String {
    let src = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenes/footing.toml")).unwrap();
    assert!(
        src.contains("duration = 2.0") && src.contains("[output]\nevery = 50\n"),
        "the footing example changed"
    );
    let s = src
        .replace("duration = 2.0", &format!("steps = {steps}"))
        .replace("[output]\nevery = 50\n", &format!("[output]\nvtk = false\n{output}"));
    format!("{s}\n{extra}\n")
}

fn run(dir: &std::path::Path, scene: &str, name: &str, flags: &[&str]) -> std::path::PathBuf {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, scene).unwrap();
    let out = dir.join(name);
    let o = std::process::Command::new(common::BIN)
        .arg("run")
        .arg(&path)
        .args(["--quiet", "--out"])
        .arg(&out)
        .args(flags)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{name}: {}", String::from_utf8_lossy(&o.stderr));
    out
}

fn fin(d: &std::path::Path) -> String {
    std::fs::read_to_string(d.join("final.json")).unwrap()
}

#[test]
fn continuum_scenes_restart_bitwise_and_thread_independently() {
    let dir = common::scratch("continuum_restart");
    let dec = "[decomposition]\nby_model = true\nnx = 2";
    let a = run(&dir, &footing(30, "checkpoint_every = 15\n", dec), "whole", &[]);
    let b = run(&dir, &footing(15, "", dec), "first", &[]);
    let from = b.join("final.json");
    let c = run(&dir, &footing(30, "", dec), "second", &["--restart", from.to_str().unwrap()]);
    assert!(fin(&a) == fin(&c), "the restarted run ends elsewhere");
    let ck = std::fs::read_to_string(a.join("checkpoint.json")).unwrap();
    assert!(ck.contains("\"continuum\"") && ck.contains("\"plastic_strain\""));
    let t = run(&dir, &footing(30, "", dec), "threads", &["--threads", "2"]);
    assert!(fin(&a) == fin(&t), "2 threads differ from 1");
    // one domain (no decomposition) restarts bitwise too
    let a = run(&dir, &footing(20, "", ""), "whole1", &[]);
    let b = run(&dir, &footing(10, "", ""), "first1", &[]);
    let c = run(
        &dir,
        &footing(20, "", ""),
        "second1",
        &["--restart", b.join("final.json").to_str().unwrap()],
    );
    assert!(fin(&a) == fin(&c), "the restarted one-domain run ends elsewhere");
    let hist = std::fs::read_to_string(a.join("history.csv")).unwrap();
    let head: Vec<&str> = hist.lines().next().unwrap().split(',').collect();
    let last: Vec<&str> = hist.lines().last().unwrap().split(',').collect();
    assert_eq!(head.len(), last.len());
    for col in ["continuum_ties", "tie_impulse", "yielding_cells"] {
        assert!(head.contains(&col), "missing column {col}");
    }
}

#[cfg(feature = "mpi")]
mod mpi_common;

/// On 2 and 4 ranks, by model and by geometry: final.json is one process's.
#[cfg(feature = "mpi")]
#[test]
fn continuum_scenes_on_ranks_give_the_one_process_result() {
    use mpi_common::*;
    let dir = scratch("continuum_ranks");
    for dec in ["[decomposition]\nby_model = true\nnx = 2", "[decomposition]\nnx = 2\nny = 2"] {
        let scene = write(&dir, "footing.toml", &footing(20, "", dec));
        let one = dir.join("one");
        let o = nscdd(&args(&scene, &one, &[]));
        assert!(o.status.success(), "{}", text(&o.stderr));
        let reference = final_json(&one);
        for n in [2, 4] {
            let out = dir.join(format!("ranks{n}"));
            let o = mpirun(&[(n, args(&scene, &out, &[]))]);
            assert!(o.status.success(), "{dec:?}, {n} ranks: {}", text(&o.stderr));
            assert!(
                final_json(&out) == reference,
                "{dec:?}, {n} ranks: final.json differs from one process"
            );
        }
    }
}
