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

/// On 2 and 4 ranks, by model and by geometry: final.json is one process's. Each
/// rank holds only its part of the grains (its halo and the tied grains,
/// `Attached::held_everywhere`; by model only with at least as many cells as ranks),
/// and a state written by 2 ranks restarts on 4 (by model: on 2) and in one
/// process to the same end, each rank reading its part of the state; with
/// compliant grains too (the band's stiffness shares).
#[cfg(feature = "mpi")]
#[test]
fn continuum_scenes_on_ranks_give_the_one_process_result() {
    use mpi_common::*;
    let dir = scratch("continuum_ranks");
    // (the grid's cells; by model a family's subdomain of a cell goes with the cell,
    // so with more ranks than cells every rank holds every body)
    for (dec, cells, geometry) in [
        ("[decomposition]\nby_model = true\nnx = 2", 2, false),
        ("[decomposition]\nnx = 2\nny = 2", 4, true),
    ] {
        let scene = write(&dir, "footing.toml", &footing(20, "", dec));
        let one = dir.join("one");
        let o = nscdd(&args(&scene, &one, &[]));
        assert!(o.status.success(), "{}", text(&o.stderr));
        let reference = final_json(&one);
        let bodies = serde_json::from_str::<serde_json::Value>(&reference).unwrap()["bodies"]
            .as_array()
            .unwrap()
            .len() as u64;
        for n in [2, 4] {
            let out = dir.join(format!("ranks{n}"));
            let o = mpirun(&[(n, args(&scene, &out, &[]))]);
            assert!(o.status.success(), "{dec:?}, {n} ranks: {}", text(&o.stderr));
            assert!(
                final_json(&out) == reference,
                "{dec:?}, {n} ranks: final.json differs from one process"
            );
            // each rank its part; by model on more ranks than cells, every body
            let held = per_rank_count(&out, "bodies_held_max");
            assert!(
                held.iter().all(|&h| (h < bodies) == (n <= cells)),
                "{dec:?}, {n} ranks: {held:?} of {bodies} bodies"
            );
            // and it loaded only its part (`FamilyKind::load_boxes`: the region's
            // mesh box, its band grains held by every rank; more ranks than cells:
            // loaded whole, none counted)
            let loaded = per_rank_count(&out, "loaded_bodies");
            assert!(
                n > cells || loaded.iter().all(|&l| l > 0 && l < bodies),
                "{dec:?}, {n} ranks: {loaded:?} of {bodies} bodies loaded"
            );
        }
        // a state written by 2 ranks restarts on 4 ranks (by model: on 2, as many as
        // its cells) and in one process to the same end
        let first = write(&dir, "first.toml", &footing(10, "", dec));
        let half = dir.join(format!("half{cells}"));
        ok(&mpirun(&[(2, args(&first, &half, &[]))]), "10 steps on 2 ranks");
        let state = half.join("final.json");
        let restart = ["--restart", state.to_str().unwrap()];
        let m = if geometry { 4 } else { 2 };
        let on = dir.join(format!("restart{cells}_{m}"));
        ok(&mpirun(&[(m, args(&scene, &on, &restart))]), "the restart on ranks");
        assert!(final_json(&on) == reference, "{dec:?}: a restart on {m} ranks ends elsewhere");
        // loaded in part (the region's mesh box, the saved state's halos), each rank
        // reading its contacts of the state
        let loaded = per_rank_count(&on, "loaded_bodies");
        assert!(
            loaded.iter().all(|&l| l > 0 && l < bodies),
            "{dec:?}: the restart on {m} ranks: {loaded:?} of {bodies} bodies loaded"
        );
        let saved: serde_json::Value = serde_json::from_str(&final_json(&half)).expect("state");
        let nc = saved["contacts"].as_array().expect("contacts").len() as u64;
        let read = per_rank_count(&on, "restart_contacts");
        assert!(
            nc > 0 && read.iter().sum::<u64>() == nc && read.iter().all(|&r| r < nc),
            "{dec:?}: the restart on {m} ranks read {read:?} of {nc} contacts"
        );
        let on1 = dir.join(format!("restart{cells}_1"));
        ok(&nscdd(&args(&scene, &on1, &restart)), "the restart in one process");
        assert!(final_json(&on1) == reference, "{dec:?}: a restart in one process ends elsewhere");
    }
    // compliant grains: the band's share 1 − α of a contact's stiffness looks up its
    // grains by id, on a rank's world holding a part as in one process
    let grains = "materials = [\"grain\", \"grain\"]\nfriction = 0.5";
    let text = footing(20, "", "[decomposition]\nnx = 2\nny = 2");
    assert!(text.contains(grains), "the footing example's grain law changed");
    let compliant = "materials = [\"grain\", \"grain\"]\nlaw = \"compliant\"\nstiffness = 1e6\ndamping = 50.0\nfriction = 0.5";
    let scene = write(&dir, "compliant.toml", &text.replace(grains, compliant));
    let one = dir.join("compliant1");
    ok(&nscdd(&args(&scene, &one, &[])), "compliant grains in one process");
    let two = dir.join("compliant2");
    ok(&mpirun(&[(2, args(&scene, &two, &[]))]), "compliant grains on 2 ranks");
    assert!(
        final_json(&two) == final_json(&one),
        "compliant grains: 2 ranks differ from one process"
    );
}

/// Two copies of a continuum scene's state that differ only in the region's state
/// (one tie impulse changed by 1e-9), each read by one of two ranks (an MPMD
/// launch): the ranks' agreement on the initial state tells them apart (exit 2),
/// as it hashes the body families' states too.
#[cfg(feature = "mpi")]
#[test]
fn ranks_reading_continuum_states_that_differ_disagree() {
    use mpi_common::*;
    let dir = scratch("continuum_digest");
    let dec = "[decomposition]\nnx = 2";
    let (early, scene) = (
        write(&dir, "first.toml", &footing(5, "", dec)),
        write(&dir, "footing.toml", &footing(10, "", dec)),
    );
    let first = dir.join("first");
    ok(&nscdd(&args(&early, &first, &[])), "the first run");
    let state = first.join("final.json");
    let with = |st: &std::path::Path, out: &str| args(&scene, &dir.join(out), &["--restart", st.to_str().unwrap()]);
    ok(&mpirun(&[(1, with(&state, "same")), (1, with(&state, "same"))]), "the same state");
    let mut saved: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&state).unwrap()).expect("state");
    // one tie's impulse
    let r = &mut saved["families"]["continuum"]["ties"][0][0];
    *r = serde_json::json!(r.as_f64().expect("a tie impulse") + 1e-9);
    let other = dir.join("other.json");
    std::fs::write(&other, serde_json::to_string_pretty(&saved).unwrap()).unwrap();
    let o = mpirun(&[(1, with(&state, "differ")), (1, with(&other, "differ"))]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("different scenes"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
