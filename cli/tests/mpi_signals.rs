//! SIGINT under `mpirun` (cargo feature `mpi`, issue 17): every rank stops after the
//! same step with a checkpoint. Needs OpenMPI's `mpirun` (the README's test command
//! installs it).
#![cfg(feature = "mpi")]

mod mpi_common;
use mpi_common::*;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// SIGINT to `mpirun` (Ctrl-C; a batch system's SIGTERM goes the same way): mpirun
/// passes it to the ranks, which agree on the step to stop after, write the
/// checkpoint of that step and stop with the message (issue 17).
#[test]
fn sigint_to_mpirun_stops_every_rank_after_the_same_step_with_a_checkpoint() {
    let dir = scratch("sigint");
    let pile = PILE2D
        .replace("steps = 15", "steps = 200000")
        .replace("\nevery = 5", "\nevery = 0\ncheckpoint_every = 50");
    let scene = dir.join("pile.toml");
    std::fs::write(&scene, format!("{pile}\n[decomposition]\nnx = 2\n")).unwrap();
    let out = dir.join("out");
    let mut c = mpirun_command(&[(2, args(&scene, &out, &[]))]);
    let mut child = c.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("mpirun");
    // a few hundred steps in, then SIGINT to mpirun
    let t0 = Instant::now();
    loop {
        let rows = std::fs::read_to_string(out.join("history.csv"))
            .map(|h| h.lines().count())
            .unwrap_or(0);
        if rows > 300 {
            break;
        }
        if child.try_wait().unwrap().is_some() || t0.elapsed() > LIMIT {
            let _ = child.kill();
            let o = child.wait_with_output().unwrap();
            panic!("the run ended or did not start: {}", text(&o.stderr));
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let st = Command::new("kill").arg("-INT").arg(child.id().to_string()).status().unwrap();
    assert!(st.success());
    let o = child.wait_with_output().unwrap();
    let err = text(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("stopped on request at the end of step"), "{err}");
    let hist = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(hist.ends_with('\n'));
    let steps = hist.lines().count() - 1;
    assert!(steps < 200000, "the run went to its end");
    let ck: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("checkpoint.json")).unwrap()).unwrap();
    assert_eq!(ck["step"].as_u64(), Some(steps as u64), "the checkpoint is the last step written");
    assert!(!out.join("final.json").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
