//! `mpirun -n P nscdd run …` (cargo feature `mpi`, issue 5): the same `final.json`
//! as the same decomposition in one process with threads, bitwise, in 2D and 3D and
//! with both schemes; decentralized messages only between ranks sharing interface
//! bodies (counted); failures of one rank end every rank promptly with its message.
//!
//! Needs OpenMPI's `mpirun` (Debian `openmpi-bin`; the README's test command
//! installs it). Ranks beyond the cores run with `--oversubscribe`.
#![cfg(feature = "mpi")]

use std::path::Path;
use std::time::{Duration, Instant};

mod common;
mod mpi_common;
use mpi_common::*;

/// A running-bond wall of 4 courses × 4 bricks bonded by mortar joints on a fixed
/// slab, under a tilted gravity.
const WALL: &str = r#"
dimension = 3
gravity = [2.0, 0.0, -9.81]
[time]
step = 1e-3
steps = 10
[solver]
tolerance = 1e-5
norm = "QM/16"
max_sweeps = 5000
[output]
every = 5
[[materials]]
name = "brick"
density = 1800.0
[[materials]]
name = "base"
density = 2400.0
[[laws]]
materials = ["brick", "brick"]
law = "mohr_coulomb"
friction = 0.6
cohesion = 2e3
[[laws]]
materials = ["brick", "base"]
friction = 0.6
[[laws]]
materials = ["base", "base"]
law = "none"
[[generate]]
kind = "brick_wall"
material = "brick"
base_material = "base"
brick = [0.2, 0.1, 0.05]
courses = 4
bricks = 4
"#;

/// The scene in one process with 2 threads, then on each rank count: final.json
/// bitwise the same, history.csv with the same rows' physics.
fn same_as_threads(scene: &Path, dir: &Path, subdomains: &str, scheme: &str, ranks: &[u32]) {
    let one = dir.join(format!("threads-{subdomains}-{scheme}"));
    let o = nscdd(&args(
        scene,
        &one,
        &["--subdomains", subdomains, "--scheme", scheme, "--threads", "2"],
    ));
    ok(&o, "the one-process run");
    let reference = final_json(&one);
    for &n in ranks {
        let out = dir.join(format!("ranks{n}-{subdomains}-{scheme}"));
        let o = mpirun(&[(n, args(scene, &out, &["--subdomains", subdomains, "--scheme", scheme]))]);
        ok(&o, &format!("{n} ranks"));
        let err = text(&o.stderr);
        assert!(err.contains(&format!("on {n} ranks")), "rank 0's summary: {err}");
        assert!(
            final_json(&out) == reference,
            "{subdomains} {scheme}: final.json on {n} ranks differs from one process"
        );
        // every column but the timings is the same step by step (the named floor's
        // reaction, summed per subdomain over the ranks, included)
        let named = std::fs::read_to_string(scene).is_ok_and(|t| t.contains("name = \"floor\""));
        for p in [&out, &one] {
            let h = std::fs::read_to_string(p.join("history.csv")).expect("history.csv");
            let head: Vec<&str> = h.lines().next().expect("header").split(',').collect();
            assert!(!named || head.contains(&"floor_fy"), "{head:?}");
        }
        assert_eq!(common::history_physics(&out), common::history_physics(&one), "history on {n} ranks");
        assert!(out.join("ranks.json").exists(), "ranks.json on {n} ranks");
    }
}

#[test]
fn two_and_four_ranks_give_the_one_process_result_2d() {
    let dir = scratch("same2d");
    let scene = write(&dir, "pile.toml", PILE2D);
    same_as_threads(&scene, &dir, "2x2", "decentralized", &[2, 4]);
    same_as_threads(&scene, &dir, "2x2", "centralized", &[2, 4]);
    same_as_threads(&scene, &dir, "3x2", "decentralized", &[4]);
    // 3 strips on 2 ranks: not contiguous when a greedy assignment balances better
    same_as_threads(&scene, &dir, "3x1", "decentralized", &[2]);
    same_as_threads(&scene, &dir, "3x1", "centralized", &[2]);
    // contacts held per rank between repartitions
    let held = write(&dir, "held.toml", &every(PILE2D, 4));
    same_as_threads(&held, &dir, "2x2", "decentralized", &[2, 4]);
    same_as_threads(&held, &dir, "3x2", "centralized", &[4]);
    // each subdomain visits its contacts from the bottom up, on any rank
    let sorted = every(PILE2D, 4).replacen("[solver]\n", "[solver]\nordering = \"sorted\"\n", 1);
    let sorted = write(&dir, "sorted.toml", &sorted);
    same_as_threads(&sorted, &dir, "2x2", "decentralized", &[4]);
    // an alert distance as large as the pile: each rank's halo, loaded in part, is
    // every body (a world of every slot, its ids not the identity)
    let wide = every(PILE2D, 4).replacen("[solver]\n", "[detection]\nalert = 0.5\n[solver]\n", 1);
    let wide = write(&dir, "wide.toml", &wide);
    same_as_threads(&wide, &dir, "2x1", "decentralized", &[2]);
    // no step at all: the state has no grid yet on ranks either (the loader's
    // provisional one is not written)
    let none_dir = scratch("same2d_no_step");
    let none = write(&none_dir, "none.toml", &PILE2D.replacen("steps = 15", "steps = 0", 1));
    same_as_threads(&none, &none_dir, "2x1", "decentralized", &[2]);
    let _ = std::fs::remove_dir_all(&none_dir);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn two_and_four_ranks_give_the_one_process_result_3d() {
    let dir = scratch("same3d");
    let scene = write(&dir, "pile3d.toml", PILE3D);
    same_as_threads(&scene, &dir, "2x2x1", "decentralized", &[2, 4]);
    same_as_threads(&scene, &dir, "2x2x2", "centralized", &[4]);
    same_as_threads(&scene, &dir, "2x2x2", "decentralized", &[4]);
    let held = write(&dir, "held.toml", &every(PILE3D, 5));
    same_as_threads(&held, &dir, "2x2x1", "decentralized", &[2, 4]);
    same_as_threads(&held, &dir, "2x2x2", "decentralized", &[4]);
    // between repartitions each rank stepped only its bodies and its halo
    let out = dir.join("ranks4-2x2x2-decentralized");
    let fin: serde_json::Value = serde_json::from_str(&final_json(&out)).expect("final.json");
    let nb = fin["bodies"].as_array().expect("bodies").len() as u64;
    for r in &per_rank(&out) {
        let (steps, stepped) = (r["steps"].as_u64().expect("steps"), r["bodies_stepped"].as_u64().expect("stepped"));
        assert!(
            stepped < steps * nb,
            "rank {}: {stepped} bodies stepped in {steps} steps of {nb}",
            r["rank"]
        );
        assert!(r["bodies_sent"].as_u64().expect("sent") > 0, "{r}");
        // and its world held only those (compact arrays): fewer than all
        let held = r["bodies_held"].as_u64().expect("held");
        assert!(held >= stepped && held < steps * nb, "rank {}: {held} bodies held", r["rank"]);
        // the other ranks' subdomains held as shells limited to the bodies near it
        // between repartitions
        assert!(r["limited_shell_steps"].as_u64().expect("limited") > 0, "{r}");
        // the rank's CPU, split into communication and compute
        let cpu = |k: &str| r[k].as_f64().unwrap_or_else(|| panic!("{k}: {r}"));
        assert!(cpu("compute_cpu_seconds") > 0.0 && cpu("wait_cpu_seconds") >= 0.0, "{r}");
        assert!(
            (cpu("cpu_seconds") - cpu("compute_cpu_seconds") - cpu("wait_cpu_seconds")).abs() < 1e-9,
            "{r}"
        );
        // its peak memory: a few MiB at least, less than this machine's
        assert!(cpu("peak_rss_mib") > 1.0 && cpu("peak_rss_mib") < 1e6, "{r}");
    }
    // the scene loaded in part: each rank built its halo and the bodies every rank
    // steps, never the whole scene; together every body
    let loaded = per_rank_count(&out, "loaded_bodies");
    assert!(loaded.iter().all(|&n| n > 0 && n < nb), "{loaded:?} of {nb}");
    assert!(loaded.iter().sum::<u64>() >= nb, "{loaded:?} of {nb}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A box sample (the deposit example, 300 steps): the history's box columns —
/// stresses from the walls' reactions, coordination numbers from the subdomains'
/// census — are the one process's on 2 and 4 ranks.
#[test]
fn a_box_sample_on_ranks_gives_the_one_process_history() {
    let dir = scratch("box");
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenes/deposit.toml")).expect("the example");
    let text = text.replace("steps = 2000", "steps = 300").replace("every = 100", "every = 0");
    let scene = write(&dir, "deposit.toml", &text);
    same_as_threads(&scene, &dir, "2x2", "decentralized", &[2, 4]);
    let h = std::fs::read_to_string(dir.join("ranks4-2x2-decentralized").join("history.csv")).expect("history");
    assert!(h.lines().next().is_some_and(|l| l.contains(",z,z_m")), "box columns");
    let held = write(&dir, "held.toml", &every(&text, 5));
    same_as_threads(&held, &dir, "2x2", "centralized", &[2, 4]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn two_ranks_give_the_one_process_result_for_a_bonded_wall() {
    // polyhedra with mortar joints: the bonds and the joint failures (a tilted
    // gravity loads them) are the same on ranks as in one process
    let dir = scratch("samewall");
    let scene = write(&dir, "wall.toml", WALL);
    same_as_threads(&scene, &dir, "2x1x2", "decentralized", &[2]);
    let fin = final_json(&dir.join("ranks2-2x1x2-decentralized"));
    assert!(fin.contains("\"bonded\": true"), "bonds in final.json");
    // multi-point contacts held per rank (their warm starts follow their points)
    let held = write(&dir, "held.toml", &every(WALL, 3));
    same_as_threads(&held, &dir, "2x1x2", "decentralized", &[2]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Threads inside ranks (hybrid): 2 ranks × 2 threads on 3 × 2 subdomains (three a
/// rank, swept in parallel), bitwise the one-process result.
/// On ranks every rank writes its piece of each VTK frame and rank 0 the `.pvtp`
/// naming them, which the `.pvd` series list: together the pieces hold the bodies
/// and contacts of the one-process frame.
#[test]
fn every_rank_writes_its_piece_of_the_vtk_frames() {
    let dir = scratch("pieces");
    // contacts on every rank, and held per rank between repartitions
    for (name, text) in [("pile", PILE2D.to_string()), ("held", every(PILE2D, 4))] {
        let scene = write(&dir, &format!("{name}.toml"), &text);
        let one = dir.join(format!("{name}-one"));
        ok(&nscdd(&args(&scene, &one, &["--subdomains", "2x2"])), "one process");
        let out = dir.join(format!("{name}-ranks"));
        ok(&mpirun(&[(4, args(&scene, &out, &["--subdomains", "2x2"]))]), "4 ranks");
        pieces_add_up(&one, &out);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn threads_inside_ranks_give_the_one_process_result() {
    let dir = scratch("hybrid");
    let scene = write(&dir, "pile.toml", PILE2D);
    let flags = ["--subdomains", "3x2", "--scheme", "decentralized"];
    let one = dir.join("one");
    ok(&nscdd(&args(&scene, &one, &flags)), "the one-process run");
    let out = dir.join("hybrid");
    ok(
        &mpirun(&[(2, args(&scene, &out, &[&flags[..], &["--threads", "2"]].concat()))]),
        "2 ranks × 2 threads",
    );
    assert!(
        final_json(&out) == final_json(&one),
        "2 ranks × 2 threads: final.json differs from one process"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

fn peers(r: &serde_json::Value) -> Vec<u64> {
    r["peers"].as_array().expect("peers").iter().map(|x| x.as_u64().unwrap()).collect()
}

/// Four strips on four ranks: rank r owns strip r (contiguous, balanced), and the
/// decentralized exchange sends one message per round to each adjacent strip's rank
/// and to no other; the centralized one only between rank 0 and each rank.
#[test]
fn decentralized_messages_go_only_to_ranks_sharing_interface_bodies() {
    let dir = scratch("messages");
    let scene = write(&dir, "pile.toml", PILE2D);
    let out = dir.join("dec");
    ok(
        &mpirun(&[(4, args(&scene, &out, &["--subdomains", "4x1", "--scheme", "decentralized"]))]),
        "4 ranks, 4x1",
    );
    let ranks = per_rank(&out);
    assert_eq!(ranks.len(), 4);
    let expected: [&[u64]; 4] = [&[1], &[0, 2], &[1, 3], &[2]];
    for (r, want) in ranks.iter().zip(expected) {
        println!("{r}");
        assert_eq!(r["last_subdomains"].as_array().unwrap().len(), 1, "one strip per rank: {r}");
        assert_eq!(peers(r), want, "rank {}: peers", r["rank"]);
        let (m, rounds) = (r["messages"].as_u64().unwrap(), r["rounds"].as_u64().unwrap());
        assert!(rounds > 0, "rank {} exchanged: {r}", r["rank"]);
        assert_eq!(m, rounds * want.len() as u64, "one message per peer and round: {r}");
    }
    // all ranks glue in the same rounds (every stage of every step)
    let rounds: Vec<u64> = ranks.iter().map(|r| r["rounds"].as_u64().unwrap()).collect();
    assert!(rounds.iter().all(|&x| x == rounds[0]), "{rounds:?}");

    let out = dir.join("cen");
    ok(
        &mpirun(&[(4, args(&scene, &out, &["--subdomains", "4x1", "--scheme", "centralized"]))]),
        "4 ranks, 4x1, centralized",
    );
    let ranks = per_rank(&out);
    for r in &ranks {
        let (m, rounds) = (r["messages"].as_u64().unwrap(), r["rounds"].as_u64().unwrap());
        if r["rank"] == 0 {
            assert_eq!(peers(r), [1, 2, 3]);
            assert_eq!(m, 3 * rounds, "the root scatters to every rank: {r}");
        } else {
            assert_eq!(peers(r), [0]);
            assert_eq!(m, rounds, "one gather message per round: {r}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_rank_count_that_does_not_fit_the_decomposition_is_bad_input() {
    let dir = scratch("fit");
    let scene = write(&dir, "pile.toml", PILE2D);
    let out = dir.join("out");
    let o = mpirun(&[(4, args(&scene, &out, &["--subdomains", "2x1"]))]);
    let err = text(&o.stderr);
    println!("{err}");
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("4 ranks for 2 subdomains"), "{err}");
    assert_eq!(err.matches("4 ranks for 2 subdomains").count(), 1, "rank 0 says it once: {err}");
    assert!(!err.contains("panicked"), "{err}");
    // the same from a state of that decomposition: the restart reads no rank's
    // part of it (too few subdomains) and the run refuses the count
    let (half, state) = (
        write(&dir, "half.toml", &PILE2D.replace("steps = 15", "steps = 8")),
        dir.join("state"),
    );
    ok(&nscdd(&args(&half, &state, &["--subdomains", "2x1"])), "the state in one process");
    let saved = state.join("final.json");
    let o = mpirun(&[(
        4,
        args(&scene, &out, &["--subdomains", "2x1", "--restart", saved.to_str().unwrap()]),
    )]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("4 ranks for 2 subdomains") && !err.contains("internal error"), "{err}");
    // no decomposition at all
    let o = mpirun(&[(2, args(&scene, &out, &[]))]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("no decomposition"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Anderson over NSCDD's stages on ranks: the dot products of the mixing summed
/// subdomain by subdomain in subdomain order, so 2 and 4 ranks give bitwise the
/// one-process (2 threads) result.
#[test]
fn anderson_on_ranks_gives_the_one_process_result() {
    let dir = scratch("anderson");
    let scene = write(
        &dir,
        "pile.toml",
        &PILE2D.replace("[solver]\n", "[solver]\nmethod = \"anderson\"\n"),
    );
    same_as_threads(&scene, &dir, "2x2", "decentralized", &[2, 4]);
    same_as_threads(&scene, &dir, "3x1", "centralized", &[2]);
    let held = write(&dir, "held.toml", &every(&std::fs::read_to_string(&scene).expect("scene"), 4));
    same_as_threads(&held, &dir, "2x2", "decentralized", &[2, 4]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Rank 1 reads a scene with an error (an MPMD launch: the ranks run different
/// files): every rank stops with exit code 2 and rank 1's message, naming the file,
/// line and key, is printed once by rank 0 and kept in OUT/error.txt.
#[test]
fn a_bad_scene_on_one_rank_stops_every_rank() {
    let dir = scratch("badscene");
    let good = write(&dir, "good.toml", PILE2D);
    let bad = write(&dir, "bad.toml", &PILE2D.replace("friction = 0.3", "friction = -0.3"));
    let out = dir.join("out");
    let t0 = Instant::now();
    let o = mpirun(&[
        (1, args(&good, &out, &["--subdomains", "2x1"])),
        (1, args(&bad, &out, &["--subdomains", "2x1"])),
    ]);
    let err = text(&o.stderr);
    println!("{err}");
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("rank 1:") && err.contains("bad.toml") && err.contains("friction"),
        "{err}"
    );
    assert!(t0.elapsed() < Duration::from_secs(60), "promptly");
    assert!(!out.join("final.json").exists());
    // printed once, by rank 0, and kept in OUT/error.txt
    assert_eq!(err.matches("must be ≥ 0").count(), 1, "{err}");
    let kept = std::fs::read_to_string(out.join("error.txt")).expect("error.txt");
    assert!(kept.contains("rank 1:") && kept.contains("friction"), "{kept}");
    // two valid but different scenes: the ranks disagree
    let other = write(&dir, "other.toml", &PILE2D.replace("friction = 0.3", "friction = 0.5"));
    let o = mpirun(&[
        (1, args(&good, &out, &["--subdomains", "2x1"])),
        (1, args(&other, &out, &["--subdomains", "2x1"])),
    ]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("different scenes"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Rank 0 cannot create its output directory while rank 1 steps on: every rank
/// stops, promptly, with rank 0's message and a non-zero code.
#[test]
fn an_unwritable_output_stops_every_rank() {
    let dir = scratch("unwritable");
    let scene = write(&dir, "pile.toml", &PILE2D.replace("steps = 15", "steps = 100000"));
    let blocker = dir.join("file");
    std::fs::write(&blocker, "a file, not a directory").unwrap();
    let out = blocker.join("out");
    let t0 = Instant::now();
    let o = mpirun(&[(2, args(&scene, &out, &["--subdomains", "2x1"]))]);
    let err = text(&o.stderr);
    println!("{err}");
    assert!(!o.status.success(), "{err}");
    // rank 0 (the output directory) or another rank (its piece of the first VTK
    // frame) may be the first to fail: either names the place
    assert!(
        err.contains(": error: cannot write the ") && err.contains("file/out: Not a directory"),
        "{err}"
    );
    assert!(t0.elapsed() < Duration::from_secs(60), "promptly, not after 100000 steps");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A body that diverges: every rank stops at that step (exit code 1), rank 0 names
/// the step and the body and keeps the history written so far.

/// A scene with deformable bodies by model (2 × 1 cells, 4 subdomains) on 2 ranks
/// (each its part of the disks, `cli/tests/deformable_ranks.rs`) and 4 (every rank
/// every disk: more ranks than cells): final.json bitwise that of one process (the
/// deformable bodies' state included; the families' parts travel as their packed
/// impulses), and the 3D foundation (2 × 2 cells by model) on 2 ranks, and the
/// whole 2D foundation on 4 ranks (its state's kept contacts merged on rank 0
/// alone); without a decomposition, refused by every rank with exit 2.
#[cfg(feature = "fem")]
#[test]
fn deformable_scenes_on_ranks_give_the_one_process_result() {
    let dir = scratch("fe_ranks");
    let src = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenes/foundation.toml")).unwrap();
    let scene = dir.join("foundation.toml");
    std::fs::write(
        &scene,
        src.replace("duration = 0.5", "steps = 30")
            .replace("[output]\n", "[output]\nvtk = false\n"),
    )
    .unwrap();
    let one = dir.join("one");
    let o = nscdd(&args(&scene, &one, &["--threads", "2"]));
    assert!(o.status.success(), "{}", text(&o.stderr));
    let reference = final_json(&one);
    assert!(reference.contains("\"deformable\""));
    for n in [2, 4] {
        let out = dir.join(format!("ranks{n}"));
        let o = mpirun(&[(n, args(&scene, &out, &[]))]);
        assert!(o.status.success(), "{n} ranks: {}", text(&o.stderr));
        assert!(final_json(&out) == reference, "{n} ranks: final.json differs from one process");
    }
    // 3D: 2 × 2 cells by model, its 400 steps (a contact of a face of the block
    // with a sphere solved on a rank that does not step the block starts from its
    // last impulse there too: without it, step 121 differed)
    let src3 = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenes/foundation3d.toml")).unwrap();
    let scene3 = dir.join("foundation3d.toml");
    std::fs::write(&scene3, src3.replace("[output]\n", "[output]\nvtk = false\n")).unwrap();
    let one3 = dir.join("one3");
    let o = nscdd(&args(&scene3, &one3, &[]));
    assert!(o.status.success(), "{}", text(&o.stderr));
    for n in [2, 4] {
        let out = dir.join(format!("ranks3d_{n}"));
        let o = mpirun(&[(n, args(&scene3, &out, &[]))]);
        assert!(o.status.success(), "3D on {n} ranks: {}", text(&o.stderr));
        assert!(
            final_json(&out) == final_json(&one3),
            "3D on {n} ranks: final.json differs from one process"
        );
    }
    // the whole foundation (disks resting on the blocks: kept contacts) on more
    // ranks than cells (by model: every rank holding every contact): rank 0 merges
    // the kept contacts alone, also in many rounds (a merge it skipped once hung
    // every rank)
    let whole = dir.join("whole.toml");
    std::fs::write(&whole, src.replace("[output]\n", "[output]\nvtk = false\n")).unwrap();
    let one = dir.join("whole_one");
    assert!(nscdd(&args(&whole, &one, &[])).status.success());
    let out = dir.join("whole_ranks4");
    let mut c = mpirun_command(&[(4, args(&whole, &out, &[]))]);
    c.env("NSCDD_MERGE_RECORDS", "3");
    let o = run_limited(c);
    assert!(o.status.success(), "the whole foundation on 4 ranks: {}", text(&o.stderr));
    let fin = final_json(&out);
    assert!(
        fin == final_json(&one),
        "the whole foundation on 4 ranks: final.json differs from one process"
    );
    let v: serde_json::Value = serde_json::from_str(&fin).expect("final.json");
    assert!(
        v["nscdd"]["kept"].as_array().is_some_and(|k| !k.is_empty()),
        "kept contacts in the state"
    );
    let plain = dir.join("plain.toml");
    let no_dd = std::fs::read_to_string(&scene).unwrap();
    let cut = no_dd.find("[decomposition]").unwrap();
    let rest = &no_dd[cut..];
    let end = rest[1..].find("\n[").map_or(no_dd.len(), |e| cut + 1 + e + 1);
    std::fs::write(&plain, format!("{}{}", &no_dd[..cut], &no_dd[end..])).unwrap();
    let out = dir.join("plain");
    let o = mpirun(&[(2, args(&plain, &out, &[]))]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("no decomposition"), "{err}");
    assert!(!out.join("final.json").exists());
}

/// Rank 0 merges the other ranks' bodies, contacts and kept contacts as it writes
/// `final.json` and the checkpoints, a bounded number of records per round
/// (`dd::rank_merge`): with two records per round (many rounds) the files are still
/// the one process's, byte for byte, and the rounds show in the reductions; also
/// written just before a repartition and with a repartition at every step. (Rigid
/// scenes hold bodies and contacts per rank: the kept contacts merged alone, the
/// other merges over before they start, are the deformable scenes' case,
/// `deformable_scenes_on_ranks_give_the_one_process_result`.)
#[test]
fn outputs_merged_in_small_rounds_are_the_one_process_files() {
    let dir = scratch("merge");
    let held = every(PILE2D, 4).replace("[output]\n", "[output]\ncheckpoint_every = 8\n");
    let cases = [
        ("held", held.clone()),
        ("last_repartitions", held.replace("steps = 15", "steps = 16")),
        ("whole", PILE2D.replace("[output]\n", "[output]\ncheckpoint_every = 8\n")),
    ];
    for (name, text) in cases {
        let scene = write(&dir, &format!("{name}.toml"), &text);
        let flags = ["--subdomains", "2x2"];
        let one = dir.join(format!("{name}-one"));
        ok(&nscdd(&args(&scene, &one, &flags)), "the one-process run");
        let reduce = |out: &Path| -> u64 { per_rank_count(out, "reduce_messages")[0] };
        let mut counts = vec![];
        for chunk in [None, Some("2")] {
            let out = dir.join(format!("{name}-ranks4-{}", chunk.unwrap_or("default")));
            let mut c = mpirun_command(&[(4, args(&scene, &out, &flags))]);
            if let Some(k) = chunk {
                c.env("NSCDD_MERGE_RECORDS", k);
            }
            ok(&run_limited(c), &format!("{name}: 4 ranks"));
            assert!(
                final_json(&out) == final_json(&one),
                "{name} {chunk:?}: final.json differs from one process"
            );
            let read = |d: &Path| std::fs::read(d.join("checkpoint.json")).expect("checkpoint.json");
            assert!(
                read(&out) == read(&one),
                "{name} {chunk:?}: checkpoint.json differs from one process"
            );
            counts.push(reduce(&out));
        }
        if name == "held" {
            assert!(counts[1] > counts[0] + 20, "rounds of two records: {counts:?} reductions");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
