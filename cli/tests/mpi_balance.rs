//! Load balance over MPI ranks (issue 20): the balanced grid's histogram added
//! over the ranks and the `rebalance` trigger give, on 2 and 4 ranks with contacts
//! held per rank, bitwise the one-process run.
#![cfg(feature = "mpi")]

mod mpi_common;
use mpi_common::*;

#[test]
fn a_balanced_grid_and_rebalancing_on_ranks_give_the_one_process_result() {
    let dir = scratch("balance_ranks");
    // balance.rs's falling lattice on 2 × 2 subdomains, balanced
    let fall = include_str!("scenes/fall.toml")
        .replace("nx = 1\nny = 2\n", "nx = 2\nny = 2\n")
        .replace("rebalance = 1.15", "rebalance = 1.15\ngrid = \"balanced\"");
    let path = write(&dir, "fall.toml", &fall);
    let one = dir.join("one");
    let o = nscdd(&args(&path, &one, &["--threads", "2"]));
    assert!(o.status.success(), "{}", text(&o.stderr));
    let reference = final_json(&one);
    let h = std::fs::read_to_string(one.join("history.csv")).unwrap();
    let col = h.lines().next().unwrap().split(',').position(|c| c == "repartitioned").unwrap();
    let reparts: Vec<u64> = h
        .lines()
        .skip(1)
        .filter(|l| l.split(',').nth(col) == Some("1"))
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert!(
        reparts.iter().any(|&s| s > 10 && (s - 1) % 40 != 0),
        "a triggered repartition: {reparts:?}"
    );
    for p in [2, 4] {
        let out = dir.join(format!("p{p}"));
        let o = mpirun(&[(p, args(&path, &out, &[]))]);
        assert!(o.status.success(), "{p} ranks: {}", text(&o.stderr));
        assert!(final_json(&out) == reference, "{p} ranks: final.json differs from one process");
        let hp = std::fs::read_to_string(out.join("history.csv")).unwrap();
        // the repartitions and imbalances of every step (the last two columns)
        let cols = |t: &str| -> Vec<String> { t.lines().map(|l| l.split(',').skip(col).collect::<Vec<_>>().join(",")).collect() };
        assert_eq!(cols(&hp), cols(&h), "{p} ranks: repartitions or imbalances differ");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The 4000-sphere pour on 2 × 2 × 2 subdomains, contacts held per rank between
/// repartitions every 100 steps: at step 111 a grain held by subdomains of both
/// ranks gains a copy (it is fresh), and its copies must start from every copy's
/// kept F_Γ, the other rank's included (`dd::rank_fresh`); before, the 2-rank run
/// left the one-process result there.
#[test]
fn the_pour_on_2x2x2_subdomains_gives_the_one_process_result() {
    let dir = scratch("pour_2x2x2");
    let pile = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scripts/bench_scenes/pile3d.toml")).expect("pile3d.toml");
    let scene = format!(
        "{}\n[decomposition]\nnx = 2\nny = 2\nnz = 2\nrepartition_every = 100\n",
        pile.replace("steps = 600", "steps = 111")
    );
    let path = write(&dir, "pour.toml", &scene);
    let one = dir.join("one");
    let o = nscdd(&args(&path, &one, &[]));
    assert!(o.status.success(), "{}", text(&o.stderr));
    let two = dir.join("two");
    let o = mpirun(&[(2, args(&path, &two, &[]))]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(final_json(&two) == final_json(&one), "2 ranks: final.json differs from one process");
    let _ = std::fs::remove_dir_all(&dir);
}
