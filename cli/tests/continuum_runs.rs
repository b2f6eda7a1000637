//! Scenes with continuum regions through the CLI (cargo feature `fem`): a restart
//! continues bitwise, `--threads 2` is bitwise one thread, and (feature `mpi`) the
//! ranks give the one-process result. docs/CONTINUUM.md.
#![cfg(feature = "fem")]

mod common;

/// The footing example shortened to `steps` steps (no VTK), with `extra` appended.
fn footing(steps: u32, output: &str, extra: &str) -> String {
    let src = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenes/footing.toml")).unwrap();
    assert!(
        src.contains("duration = 3.5") && src.contains("[output]\nevery = 50\n"),
        "the footing example changed"
    );
    let s = src
        .replace("duration = 3.5", &format!("steps = {steps}"))
        .replace("[output]\nevery = 50\n", &format!("[output]\nvtk = false\n{output}"));
    format!("{s}\n{extra}\n")
}

fn fin(d: &std::path::Path) -> String {
    std::fs::read_to_string(d.join("final.json")).unwrap()
}

#[test]
fn continuum_scenes_restart_bitwise_and_thread_independently() {
    let dir = common::scratch("continuum_restart");
    let dec = "[decomposition]\nby_model = true\nnx = 2";
    let a = common::run_scene(&dir, "whole", &footing(30, "checkpoint_every = 15\n", dec), &[]);
    let b = common::run_scene(&dir, "first", &footing(15, "", dec), &[]);
    let from = b.join("final.json");
    let c = common::run_scene(&dir, "second", &footing(30, "", dec), &["--restart", from.to_str().unwrap()]);
    assert!(fin(&a) == fin(&c), "the restarted run ends elsewhere");
    let ck = std::fs::read_to_string(a.join("checkpoint.json")).unwrap();
    assert!(ck.contains("\"continuum\"") && ck.contains("\"plastic_strain\""));
    let t = common::run_scene(&dir, "threads", &footing(30, "", dec), &["--threads", "2"]);
    assert!(fin(&a) == fin(&t), "2 threads differ from 1");
    // one domain (no decomposition) restarts bitwise too
    let a = common::run_scene(&dir, "whole1", &footing(20, "", ""), &[]);
    let b = common::run_scene(&dir, "first1", &footing(10, "", ""), &[]);
    let c = common::run_scene(
        &dir,
        "second1",
        &footing(20, "", ""),
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
