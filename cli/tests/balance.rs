//! Load balance of the subdomains (issue 20): `[decomposition] grid = "balanced"`
//! (cuts that split the contact points evenly) and `rebalance` (a repartition when
//! the imbalance has grown since the last one). The `imbalance` and `repartitioned`
//! history columns; the same bits with threads and across a restart; bad keys are
//! exit-2 errors naming them.

mod common;

use common::*;
use std::path::Path;

/// A wide bed of disks with a tall column at its left end: the contact points'
/// box is tall, their mass at the bottom. 1 × 2 subdomains (cut along y).
const BED: &str = r#"
[time]
step = 1e-3
steps = 20
[solver]
tolerance = 1e-4
max_sweeps = 2000
[output]
vtk = false
[decomposition]
nx = 1
ny = 2
repartition_every = 5
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
position = [0.2, -0.005]
length = 0.42
thickness = 0.01
fixed = true
[[generate]]
kind = "square_lattice"
material = "m"
radius = 0.01
origin = [0.01, 0.01]
nx = 20
ny = 4
spacing = 0.02
[[generate]]
kind = "square_lattice"
material = "m"
radius = 0.01
origin = [0.01, 0.09]
nx = 1
ny = 12
spacing = 0.02
"#;

/// A lattice of disks falling on a floor between two walls: the contacts appear
/// at the bottom and rise with the pile; 1 × 2 subdomains, re-partitioned every 40
/// steps and when the imbalance grows by 15 % (`scenes/fall.toml`, shared with
/// `mpi_balance.rs`).
const FALL: &str = include_str!("scenes/fall.toml");

/// (step, repartitioned, imbalance) of each history row.
fn balance(out: &Path) -> Vec<(u64, bool, f64)> {
    let h = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let head: Vec<&str> = h.lines().next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|c| *c == n).unwrap_or_else(|| panic!("column {n}"));
    let (r, i) = (col("repartitioned"), col("imbalance"));
    h.lines()
        .skip(1)
        .map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            (v[0].parse().unwrap(), v[r] == "1", v[i].parse().unwrap())
        })
        .collect()
}

#[test]
fn a_balanced_grid_splits_the_contacts_evenly() {
    let dir = scratch("balanced_grid");
    let uniform = balance(&run_scene(&dir, "uniform", BED, &[]));
    let bal = run_scene(
        &dir,
        "balanced",
        &BED.replace("repartition_every = 5", "repartition_every = 5\ngrid = \"balanced\""),
        &[],
    );
    let balanced = balance(&bal);
    let mean = |b: &[(u64, bool, f64)]| b.iter().map(|x| x.2).sum::<f64>() / b.len() as f64;
    // the uniform cut at mid-height leaves the bed's contacts in the lower cell
    assert!(mean(&uniform) > 1.5, "uniform: {uniform:?}");
    // (the lattice's contacts lie in rows: a cut falls between two of them)
    assert!(
        mean(&balanced) < 1.2 && mean(&balanced) < mean(&uniform) - 0.3,
        "balanced: {balanced:?}"
    );
    let fin = std::fs::read_to_string(bal.join("final.json")).unwrap();
    assert!(fin.contains("\"cuts\""), "the balanced cuts are saved with the grid");
    // two threads: the same bits
    let two = run_scene(
        &dir,
        "balanced2",
        &BED.replace("repartition_every = 5", "repartition_every = 5\ngrid = \"balanced\""),
        &["--threads", "2"],
    );
    assert!(
        std::fs::read_to_string(two.join("final.json")).unwrap() == fin,
        "2 threads: final.json differs"
    );
    assert_eq!(history_physics(&two), history_physics(&bal));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_growing_imbalance_re_partitions_and_restarts_bitwise() {
    let dir = scratch("rebalance");
    let whole = run_scene(&dir, "whole", FALL, &[]);
    let b = balance(&whole);
    let periodic = |s: u64| s <= 10 || (s - 1) % 40 == 0;
    let extra: Vec<u64> = b.iter().filter(|x| x.1 && !periodic(x.0)).map(|x| x.0).collect();
    assert!(!extra.is_empty(), "no repartition beside the periodic ones: {b:?}");
    for w in b.windows(2).filter(|w| w[0].0 > 10) {
        assert!(!(w[0].1 && w[1].1), "two repartitions in a row at step {}", w[1].0);
    }
    // each triggered one follows a step whose imbalance exceeded 1.15 × the last
    // repartition's
    for &s in &extra {
        let last = b.iter().filter(|x| x.1 && x.0 < s - 1).last().unwrap().2;
        assert!(b[(s - 3) as usize].2 > 1.15 * last, "step {s}: {b:?}");
    }
    // without `rebalance`: only the periodic ones
    let plain = balance(&run_scene(&dir, "plain", &FALL.replace("rebalance = 1.15\n", ""), &[]));
    assert!(plain.iter().all(|x| !x.1 || periodic(x.0)));
    // threads, and a restart between a trigger and its repartition's reference
    let two = run_scene(&dir, "two", FALL, &["--threads", "2"]);
    let fin = std::fs::read_to_string(whole.join("final.json")).unwrap();
    assert!(
        std::fs::read_to_string(two.join("final.json")).unwrap() == fin,
        "2 threads: final.json differs"
    );
    // stopped after the step that decided a repartition, before it
    let stop = extra[0] - 1;
    let first = run_scene(&dir, "first", &FALL.replace("steps = 200", &format!("steps = {stop}")), &[]);
    let state = first.join("final.json");
    let cont = run_scene(&dir, "cont", FALL, &["--restart", state.to_str().unwrap()]);
    assert!(
        std::fs::read_to_string(cont.join("final.json")).unwrap() == fin,
        "the restart at step {stop} ends elsewhere"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

fn with_decomposition(body: &str) -> String {
    format!("{BASE}\n[decomposition]\n{body}\n")
}

#[test]
fn a_rebalance_of_at_most_one_is_refused() {
    check_bad(&Case {
        name: "dd_rebalance_one",
        scene: with_decomposition("nx = 1\nny = 1\nrepartition_every = 10\nrebalance = 1.0"),
        key: "decomposition.rebalance",
        marker: "rebalance = 1.0",
    });
}

#[test]
fn a_rebalance_with_a_repartition_at_every_step_is_refused() {
    check_bad(&Case {
        name: "dd_rebalance_every",
        scene: with_decomposition("nx = 1\nny = 1\nrebalance = 1.2"),
        key: "decomposition.rebalance",
        marker: "rebalance = 1.2",
    });
}

#[test]
fn an_unknown_grid_is_refused() {
    check_bad(&Case {
        name: "dd_grid",
        scene: with_decomposition("nx = 1\nny = 1\ngrid = \"octree\""),
        key: "decomposition.grid",
        marker: "grid = \"octree\"",
    });
}
