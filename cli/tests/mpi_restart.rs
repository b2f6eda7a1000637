//! Restarts on MPI ranks (cargo feature `mpi`, issue 20): a state written by P
//! ranks continues on P′ ranks, and in one process, bitwise as the uninterrupted
//! one-process run, in 2D and 3D, written between two repartitions or just before
//! one; the first step after a restart, like every other, runs with each rank's
//! part of the bodies and contacts (contacts held per rank).
#![cfg(feature = "mpi")]

use std::path::Path;

mod mpi_common;
use mpi_common::*;

/// A state written by 2 ranks continues on 4 ranks and in one process, and a state
/// written by 4 ranks on 2: bitwise the uninterrupted one-process run (F_Γ of
/// every rank's subdomains is gathered into the state).
#[test]
fn a_state_written_by_p_ranks_restarts_on_other_rank_counts() {
    let dir = scratch("restart_ranks");
    let flags = ["--subdomains", "2x2", "--scheme", "decentralized"];
    // every rank holding every contact; contacts held per rank, re-partitioned every
    // 3 steps (the state written between two repartitions) and every 4 (just
    // before one)
    for (tag, every_k) in [("", None), ("held-", Some(3)), ("rep-", Some(4))] {
        let scene = |text: &str| every_k.map_or(text.to_string(), |k| every(text, k));
        let whole = write(&dir, &format!("{tag}pile.toml"), &scene(PILE2D));
        let half = write(&dir, &format!("{tag}half.toml"), &scene(&PILE2D.replace("steps = 15", "steps = 8")));
        let reference = uninterrupted(&dir, &whole, &flags, tag);
        restarts_match(&dir, &whole, &half, &reference, &flags, tag);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Two copies of a state that differ in one contact's impulse, in one body's
/// velocity or in one interface multiplier, read in part by two ranks (an MPMD
/// launch): the ranks' agreement tells them apart (exit 2), as every rank hashes
/// every contact and body it reads, kept or not, and the NSCDD state.
#[test]
fn ranks_reading_states_that_differ_in_a_contact_disagree() {
    let dir = scratch("restart_digest");
    let (whole, state) = pile_state_on_two_ranks(&dir);
    let flags = FLAGS2X2;
    let out = dir.join("then");
    let with = |st: &Path, out: &Path| args(&whole, out, &[&flags[..], &["--restart", st.to_str().unwrap()]].concat());
    // the same state on both ranks: it runs, reading the contacts in part
    ok(&mpirun(&[(1, with(&state, &out)), (1, with(&state, &out))]), "the same state");
    contacts_read_in_part(&state, &out);
    // a copy changed by `edit` on the second rank: the ranks disagree
    let (other, out2) = (dir.join("other.json"), dir.join("then2"));
    let disagree = |edit: &dyn Fn(&mut serde_json::Value)| {
        let mut saved: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&state).unwrap()).expect("state");
        edit(&mut saved);
        std::fs::write(&other, serde_json::to_string_pretty(&saved).unwrap()).unwrap();
        let o = mpirun(&[(1, with(&state, &out2)), (1, with(&other, &out2))]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains("different scenes"), "{err}");
    };
    // one contact's impulse
    disagree(&|s| {
        let last = s["contacts"].as_array_mut().expect("contacts").last_mut().expect("a contact");
        let rn = last["r"][0].as_f64().expect("r");
        last["r"][0] = serde_json::json!(rn * 1.5 + 1e-3);
    });
    // the bodies too are read in part: one body's velocity
    disagree(&|s| {
        let v = s["bodies"][3]["velocity"][0].as_f64().expect("velocity");
        s["bodies"][3]["velocity"][0] = serde_json::json!(v + 1e-9);
    });
    // and the NSCDD state alone (one interface multiplier)
    disagree(&|s| {
        let f = s["nscdd"]["f_gamma"][0][2][0].as_f64().expect("an interface multiplier");
        s["nscdd"]["f_gamma"][0][2][0] = serde_json::json!(f + 1e-9);
    });
    let _ = std::fs::remove_dir_all(&dir);
}

/// A state the restart refuses, read by ranks that would load the scene in part
/// (a body's id out of order, a body's kind changed, a body too few): each is
/// refused with the one-process message (exit 2), as the first pass over the
/// state leaves such a state to the whole restart.
#[test]
fn a_bad_state_on_ranks_is_refused_as_in_one_process() {
    let dir = scratch("restart_bad");
    let (whole, state) = pile_state_on_two_ranks(&dir);
    let flags = FLAGS2X2;
    let saved: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&state).unwrap()).expect("state");
    let bad = |what: &str, edit: &dyn Fn(&mut Vec<serde_json::Value>)| {
        let mut s = saved.clone();
        edit(s["bodies"].as_array_mut().expect("bodies"));
        let bad_state = dir.join(format!("{what}.json"));
        std::fs::write(&bad_state, serde_json::to_string_pretty(&s).unwrap()).unwrap();
        let with = |out: &str| {
            args(
                &whole,
                &dir.join(out),
                &[&flags[..], &["--restart", bad_state.to_str().unwrap()]].concat(),
            )
        };
        let (one, on4) = (nscdd(&with(&format!("{what}1"))), mpirun(&[(4, with(&format!("{what}4")))]));
        let (e1, e4) = (text(&one.stderr), text(&on4.stderr));
        assert_eq!((one.status.code(), on4.status.code()), (Some(2), Some(2)), "{what}: {e1} / {e4}");
        let message = e1.lines().find(|l| l.contains(".json")).expect("the message names the file");
        assert!(e4.contains(message.trim()), "{what}: one process: {e1}; 4 ranks: {e4}");
    };
    bad("id", &|b| b[5]["id"] = serde_json::json!(6));
    bad("kind", &|b| b[7]["kind"] = serde_json::json!("polygon"));
    bad("count", &|b| {
        b.pop();
    });
    let _ = std::fs::remove_dir_all(&dir);
}

/// The 2 × 2 decomposition, decentralized, of the tests restarting the pile.
const FLAGS2X2: [&str; 4] = ["--subdomains", "2x2", "--scheme", "decentralized"];

/// The 2D pile re-partitioned every 3 steps, 15 steps (`whole`, written in `dir`),
/// and its state after 8 steps on 2 ranks ([`FLAGS2X2`]).
fn pile_state_on_two_ranks(dir: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let whole = write(dir, "pile.toml", &every(PILE2D, 3));
    let half = write(dir, "half.toml", &every(&PILE2D.replace("steps = 15", "steps = 8"), 3));
    let a = dir.join("first");
    ok(&mpirun(&[(2, args(&half, &a, &FLAGS2X2))]), "8 steps on 2 ranks");
    (whole, a.join("final.json"))
}

/// `whole` in one process with 2 threads: its final.json.
fn uninterrupted(dir: &Path, whole: &Path, flags: &[&str], tag: &str) -> String {
    let one = dir.join(format!("{tag}one"));
    ok(
        &nscdd(&args(whole, &one, &[flags, &["--threads", "2"]].concat())),
        &format!("{tag}uninterrupted"),
    );
    final_json(&one)
}

/// `half` on P ranks, then `whole` restarted from its state on P′: the reference's
/// final.json; with contacts held per rank (`[decomposition] repartition_every`)
/// each rank of the restart on 4 ranks held fewer bodies than all at every step,
/// the first one included; and the restarted runs' frames in pieces.
fn restarts_match(dir: &Path, whole: &Path, half: &Path, reference: &str, flags: &[&str], tag: &str) {
    for (first, then) in [(2, 4), (2, 1), (4, 2)] {
        let a = dir.join(format!("{tag}first{first}-{then}"));
        ok(&mpirun(&[(first, args(half, &a, flags))]), &format!("8 steps on {first} ranks"));
        assert!(final_json(&a).contains("\"f_gamma\""), "the NSCDD state on {first} ranks");
        let b = dir.join(format!("{tag}then{first}-{then}"));
        let state = a.join("final.json");
        let rest = args(whole, &b, &[flags, &["--restart", state.to_str().unwrap()]].concat());
        let o = if then == 1 { nscdd(&rest) } else { mpirun(&[(then, rest)]) };
        ok(&o, &format!("the restart on {then} rank(s)"));
        assert!(
            final_json(&b) == reference,
            "{tag}{first} ranks then {then}: final.json differs from the uninterrupted run"
        );
        // (on 4 ranks each holds one of the 4 cells and its halo; on 2 ranks two
        // cells may be opposite corners, whose halo is the whole small pile)
        if then == 4 && std::fs::read_to_string(whole).unwrap().contains("repartition_every") {
            held_less_than_all(&b);
        }
        if then > 1 {
            contacts_read_in_part(&state, &b);
            bodies_loaded_in_part(&b, then == 4);
        }
    }
    // the restarted runs' frames, the one at the restart included, in pieces that
    // hold each body and contact once
    let one = dir.join(format!("{tag}then2-1"));
    let frames = (0..)
        .take_while(|f| one.join("vtk").join(format!("bodies_{f:06}.vtp")).exists())
        .count() as u32;
    assert!(frames >= 2, "{tag}: {frames} frames");
    pieces_add_up_in(&one, &dir.join(format!("{tag}then2-4")), frames, 4);
    pieces_add_up_in(&one, &dir.join(format!("{tag}then4-2")), frames, 2);
}

/// A 3D pile (spheres rolling under a tilted gravity: rotations, friction) written
/// by 2 ranks just before a repartition and between two, restarted on 4, 1 and 2
/// ranks: bitwise the uninterrupted run (an isotropic body's M̂⁻¹, recomputed at the
/// saved orientation, is its own at any orientation).
#[test]
fn a_3d_state_restarts_on_other_rank_counts() {
    let dir = scratch("restart_ranks3");
    let flags = ["--subdomains", "2x2x1", "--scheme", "decentralized"];
    let whole = write(&dir, "pile3d.toml", &every(&PILE3D.replace("steps = 10", "steps = 16"), 5));
    let reference = uninterrupted(&dir, &whole, &flags, "");
    for (at, tag) in [(10, "rep-"), (12, "mid-")] {
        let half = write(
            &dir,
            &format!("half{at}.toml"),
            &every(&PILE3D.replace("steps = 10", &format!("steps = {at}")), 5),
        );
        restarts_match(&dir, &whole, &half, &reference, &flags, tag);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The restart from `state` in `out` read the state's contacts in part: each rank
/// loaded only its own (`restart_contacts` in ranks.json), each contact one rank.
fn contacts_read_in_part(state: &Path, out: &Path) {
    let saved: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(state).unwrap()).expect("state");
    let nc = saved["contacts"].as_array().expect("contacts").len() as u64;
    let loaded = per_rank_count(out, "restart_contacts");
    assert!(nc > 0, "{}: a state without contacts", state.display());
    assert_eq!(loaded.iter().sum::<u64>(), nc, "{}: {loaded:?} of {nc}", out.display());
    assert!(loaded.iter().all(|&n| n < nc), "{}: {loaded:?} of {nc}", out.display());
}

/// The restart in `out` loaded the scene in part: every body on some rank, and
/// (`fewer`: one cell a rank) each rank fewer than all (`loaded_bodies` in
/// ranks.json, before the first step's drop).
fn bodies_loaded_in_part(out: &Path, fewer: bool) {
    let fin: serde_json::Value = serde_json::from_str(&final_json(out)).expect("final.json");
    let nb = fin["bodies"].as_array().expect("bodies").len() as u64;
    let loaded = per_rank_count(out, "loaded_bodies");
    assert!(loaded.iter().sum::<u64>() >= nb, "{}: {loaded:?} of {nb}", out.display());
    assert!(!fewer || loaded.iter().all(|&n| n < nb), "{}: {loaded:?} of {nb}", out.display());
}

/// Each rank of the run in `out` held fewer bodies than all at every step (the
/// most it held in one step: the first after the restart included).
fn held_less_than_all(out: &Path) {
    let fin: serde_json::Value = serde_json::from_str(&final_json(out)).expect("final.json");
    let nb = fin["bodies"].as_array().expect("bodies").len() as u64;
    for (r, most) in per_rank_count(out, "bodies_held_max").into_iter().enumerate() {
        assert!(most < nb, "{}: rank {r}: {most} bodies held in a step, of {nb}", out.display());
    }
}

/// A scene with deformable bodies by model (the 2D foundation: FE blocks under
/// disks, kept contacts, the families' states) written by 2 ranks continues on 1, 2
/// and 4 ranks bitwise as the uninterrupted one-process run.
#[cfg(feature = "fem")]
#[test]
fn a_deformable_state_written_by_ranks_restarts_on_other_rank_counts() {
    let dir = scratch("restart_fe");
    let src = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenes/foundation.toml")).unwrap();
    assert!(src.contains("duration = 0.5") && src.contains("[output]\n"), "the example changed");
    let src = src.replace("[output]\n", "[output]\nvtk = false\n");
    let whole = write(&dir, "whole.toml", &src.replace("duration = 0.5", "steps = 400"));
    let half = write(&dir, "half.toml", &src.replace("duration = 0.5", "steps = 250"));
    let reference = uninterrupted(&dir, &whole, &[], "fe-");
    let a = dir.join("half2");
    ok(&mpirun(&[(2, args(&half, &a, &[]))]), "250 steps on 2 ranks");
    let state = a.join("final.json");
    assert!(final_json(&a).contains("\"deformable\""), "the families' states");
    let v: serde_json::Value = serde_json::from_str(&final_json(&a)).expect("final.json");
    assert!(
        v["nscdd"]["kept"].as_array().is_some_and(|k| !k.is_empty()),
        "kept contacts in the state"
    );
    for then in [1, 2, 4] {
        let b = dir.join(format!("then{then}"));
        let rest = args(&whole, &b, &["--restart", state.to_str().unwrap()]);
        let o = if then == 1 { nscdd(&rest) } else { mpirun(&[(then, rest)]) };
        ok(&o, &format!("the restart on {then} rank(s)"));
        assert!(
            final_json(&b) == reference,
            "2 ranks then {then}: final.json differs from the uninterrupted run"
        );
        // by model on as many ranks as cells, read in part as by geometry; the
        // disks have moved onto the block since the scene's poses: the bodies near
        // it are chosen at the saved ones
        if then == 2 {
            contacts_read_in_part(&state, &b);
            bodies_loaded_in_part(&b, true);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
