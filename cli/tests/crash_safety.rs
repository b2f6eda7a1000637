//! Crash-safe outputs (issue 17): SIGINT stops a run at the end of a step with a
//! checkpoint (exit 130); after `kill -9` at any moment, history.csv holds whole
//! lines and `--restart` from the last checkpoint reaches bitwise the final state of
//! an uninterrupted run.
#![cfg(unix)]
mod common;
use common::*;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A pile of 600 disks settling on a floor for 600 steps, 2 × 2 subdomains (the NSCDD state is
/// part of what a restart must carry), a checkpoint every 10 steps.
fn scene(dir: &Path) -> PathBuf {
    let text = format!(
        "{}\n[[generate]]\nkind = \"square_lattice\"\nmaterial = \"grain\"\nradius = 0.01\norigin = [0.2, 0.011]\nnx = 30\nny = 20\nspacing = 0.0201\n[decomposition]\nnx = 2\nny = 2\n[output]\nvtk = true\nevery = 25\ncheckpoint_every = 10\n",
        BASE.replace("steps = 10", "steps = 600")
    );
    let p = dir.join("pile.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn start(scene: &Path, out: &Path, extra: &[&str]) -> Child {
    Command::new(BIN)
        .arg("run")
        .arg(scene)
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits until `out/history.csv` has more than `rows` rows (or 60 s).
fn wait_rows(out: &Path, rows: usize) {
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_secs(60) {
        let n = std::fs::read_to_string(out.join("history.csv"))
            .map(|h| h.lines().count())
            .unwrap_or(0);
        if n > rows + 1 {
            return;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    panic!("the run did not reach {rows} steps");
}

fn final_of(out: &Path) -> String {
    std::fs::read_to_string(out.join("final.json")).unwrap()
}

fn run_to_end(scene: &Path, out: &Path, extra: &[&str]) {
    let o = start(scene, out, extra).wait_with_output().unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
}

#[test]
fn sigint_stops_at_a_step_with_a_checkpoint_and_the_restart_is_bitwise() {
    let dir = scratch("sigint");
    let scene = scene(&dir);
    let whole = dir.join("whole");
    run_to_end(&scene, &whole, &[]);
    let out = dir.join("stopped");
    let child = start(&scene, &out, &[]);
    wait_rows(&out, 15);
    let st = Command::new("kill").arg("-INT").arg(child.id().to_string()).status().unwrap();
    assert!(st.success());
    let o = child.wait_with_output().unwrap();
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(
        err.contains("stopped on request at the end of step") && err.contains("checkpoint.json"),
        "{err}"
    );
    let hist = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(hist.ends_with('\n'));
    let steps = hist.lines().count() - 1;
    let ck: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("checkpoint.json")).unwrap()).unwrap();
    assert_eq!(ck["step"].as_u64(), Some(steps as u64), "the checkpoint is the last step written");
    assert!(out.join("bodies.pvd").exists(), "the VTK series is closed");
    let again = dir.join("again");
    run_to_end(&scene, &again, &["--restart", out.join("checkpoint.json").to_str().unwrap()]);
    assert!(
        final_of(&again) == final_of(&whole),
        "the restart from the interrupted run ends elsewhere"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn kill_9_at_any_moment_leaves_whole_lines_and_a_checkpoint_that_restarts_bitwise() {
    let dir = scratch("kill9");
    let scene = scene(&dir);
    let whole = dir.join("whole");
    run_to_end(&scene, &whole, &[]);
    let reference = final_of(&whole);
    // kills at rows drawn from a fixed sequence, and a few milliseconds after them
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    for k in 0..4 {
        x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let rows = 12 + (x >> 33) as usize % 440;
        let extra_ms = (x >> 20) % 7;
        let out = dir.join(format!("killed{k}"));
        let mut child = start(&scene, &out, &[]);
        wait_rows(&out, rows);
        std::thread::sleep(Duration::from_millis(extra_ms));
        child.kill().unwrap();
        child.wait().unwrap();
        assert!(!out.join("final.json").exists(), "kill {k} came after the run's end");
        let hist = std::fs::read_to_string(out.join("history.csv")).unwrap();
        assert!(hist.ends_with('\n'), "kill {k} after {rows} rows: half a line in history.csv");
        let ck = out.join("checkpoint.json");
        let text_ck = std::fs::read_to_string(&ck).unwrap();
        assert!(
            serde_json::from_str::<serde_json::Value>(&text_ck).is_ok(),
            "kill {k}: a partial checkpoint"
        );
        let again = dir.join(format!("again{k}"));
        run_to_end(&scene, &again, &["--restart", ck.to_str().unwrap()]);
        assert!(
            final_of(&again) == reference,
            "kill {k} after {rows} rows: the restart ends elsewhere"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
