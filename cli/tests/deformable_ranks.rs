//! Deformable (finite-element) bodies on MPI ranks decomposed by geometry: each
//! rank holds only its part of the rigid bodies (its halo and the bodies near the
//! deformable ones, `Attached::reach`, which every rank steps), and the ranks give
//! the one-process `final.json`, in 2D and 3D, and across a restart on another rank
//! count, also for a free block thrown onto disks (bodies entering and leaving its
//! reach); by model too, with at least as many grid cells as ranks (with more ranks,
//! every rank holds every body: `mpi.rs`).
#![cfg(all(feature = "fem", feature = "mpi"))]

mod common;
mod mpi_common;
use mpi_common::*;

/// The example `name` with `steps` steps, no VTK, decomposed by geometry (`dec`
/// instead of `by_model`), its grains' `origin` replaced by `lowered`: the lowest
/// layer within the alert distance of the foundation from the first step.
fn scene(name: &str, (steps, dec): (u32, &str), (origin, lowered): (&str, &str)) -> String {
    let src = std::fs::read_to_string(format!("{}/../examples/scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"))).unwrap();
    let by_model = src.find("by_model = true\n").expect("a by-model decomposition");
    let end = src[by_model..].find("\n\n").map_or(src.len(), |e| by_model + e);
    let duration = src.find("duration = ").expect("a duration");
    let line_end = duration + src[duration..].find('\n').unwrap();
    assert!(src.contains(origin), "{name}: the grains' origin changed");
    let s = format!("{}{dec}{}", &src[..by_model], &src[end..]);
    let s = s.replace(&src[duration..line_end], &format!("steps = {steps}"));
    s.replace("[output]\n", "[output]\nvtk = false\n").replace(origin, lowered)
}

/// The number of bodies in a `final.json`.
fn bodies(fin: &str) -> u64 {
    let v: serde_json::Value = serde_json::from_str(fin).expect("final.json");
    v["bodies"].as_array().expect("bodies").len() as u64
}

/// The most deformable contacts of a step in `out`'s history.
fn most_fe_contacts(out: &std::path::Path) -> f64 {
    common::history_column(out, "deformable_contacts").into_iter().fold(0.0, f64::max)
}

/// Runs `scene` (`steps` steps, a grid of `cells` cells) in one process and on each
/// of `ranks`: the same `final.json` and history (but its timings); each rank
/// holding fewer bodies than the scene when there are at least as many cells as
/// ranks. Returns the one-process `final.json`.
fn same_on_ranks(dir: &std::path::Path, tag: &str, (scene, steps, cells): (&std::path::Path, u64, u32), ranks: &[u32]) -> String {
    let one = dir.join(format!("{tag}_one"));
    ok(&nscdd(&args(scene, &one, &[])), &format!("{tag} in one process"));
    let reference = final_json(&one);
    let bodies = bodies(&reference);
    assert!(most_fe_contacts(&one) > 0.0, "{tag}: no deformable contact");
    for &n in ranks {
        let out = dir.join(format!("{tag}_ranks{n}"));
        ok(&mpirun(&[(n, args(scene, &out, &[]))]), &format!("{tag} on {n} ranks"));
        assert!(
            final_json(&out) == reference,
            "{tag}, {n} ranks: final.json differs from one process"
        );
        assert_eq!(
            common::history_physics(&out),
            common::history_physics(&one),
            "{tag}, {n} ranks: the history differs from one process"
        );
        // (summed over the steps: a fresh run's first step holds the provisional
        // grid's halo and the real one's, on small samples nearly every body)
        let held = per_rank_count(&out, "bodies_held");
        assert!(
            held.iter().all(|&h| (h < steps * bodies) == (n <= cells)),
            "{tag}, {n} ranks: {held:?} bodies held over {steps} steps of {bodies} bodies"
        );
        // loaded in part (`FamilyKind::load_boxes`): no rank built every body (more
        // ranks than cells: loaded whole, every rank steps every body, none counted)
        let loaded = per_rank_count(&out, "loaded_bodies");
        assert!(
            n > cells || loaded.iter().all(|&l| l > 0 && l < bodies),
            "{tag}, {n} ranks: {loaded:?} bodies loaded of {bodies}"
        );
    }
    reference
}

/// A restart from `state` on `n` ranks (one cell each) loaded its part: no rank
/// built every body, and each read only its own contacts of the state, each
/// contact one rank (`loaded_bodies`, `restart_contacts` in ranks.json).
fn restarted_in_part(out: &std::path::Path, reference: &str, state: &std::path::Path, n: usize) {
    let loaded = per_rank_count(out, "loaded_bodies");
    let all = bodies(reference);
    assert!(
        loaded.len() == n && loaded.iter().all(|&l| l > 0 && l < all),
        "{loaded:?} bodies loaded of {all}"
    );
    let saved: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(state).expect("state")).expect("state");
    let nc = saved["contacts"].as_array().expect("contacts").len() as u64;
    let read = per_rank_count(out, "restart_contacts");
    assert!(nc > 0, "a state without contacts");
    assert_eq!(read.iter().sum::<u64>(), nc, "{read:?} contacts read of {nc}");
    assert!(read.iter().all(|&r| r < nc), "{read:?} contacts read of {nc}");
}

#[test]
fn deformable_scenes_by_geometry_hold_bodies_per_rank() {
    let dir = scratch("fe_held");
    let lattice = ("origin = [0.2, 0.62]", "origin = [0.2, 0.56]");
    let dec = "nx = 4";
    let s2 = write(&dir, "foundation.toml", &scene("foundation", (40, dec), lattice));
    let reference = same_on_ranks(&dir, "2d", (&s2, 40, 4), &[2, 4]);
    // a state written by 2 ranks restarts on 4 ranks and in one process
    let first = write(&dir, "first.toml", &scene("foundation", (20, dec), lattice));
    let half = dir.join("half");
    ok(&mpirun(&[(2, args(&first, &half, &[]))]), "20 steps on 2 ranks");
    let state = half.join("final.json");
    let restart = ["--restart", state.to_str().unwrap()];
    let on4 = dir.join("restart4");
    ok(&mpirun(&[(4, args(&s2, &on4, &restart))]), "the restart on 4 ranks");
    assert!(final_json(&on4) == reference, "a restart on 4 ranks ends elsewhere");
    restarted_in_part(&on4, &reference, &state, 4);
    let on1 = dir.join("restart1");
    ok(&nscdd(&args(&s2, &on1, &restart)), "the restart in one process");
    assert!(final_json(&on1) == reference, "a restart in one process ends elsewhere");
    // by model (the block's contacts in subdomains of their own, each on its cell's
    // rank): held per rank too with as many cells as ranks; on more ranks every
    // rank holds every body, and the outputs' sums are still added as in one process
    let sm = write(
        &dir,
        "by_model.toml",
        &scene("foundation", (40, "by_model = true\nnx = 2"), lattice),
    );
    let reference = same_on_ranks(&dir, "by_model", (&sm, 40, 2), &[2, 4]);
    // restarted by model on 2 ranks from a state of 2: each rank reads its part of
    // the state, as by geometry
    let first = write(
        &dir,
        "by_model20.toml",
        &scene("foundation", (20, "by_model = true\nnx = 2"), lattice),
    );
    let half = dir.join("by_model_half");
    ok(&mpirun(&[(2, args(&first, &half, &[]))]), "20 steps by model on 2 ranks");
    let state = half.join("final.json");
    let on2 = dir.join("by_model_restart2");
    let restart = ["--restart", state.to_str().unwrap()];
    ok(&mpirun(&[(2, args(&sm, &on2, &restart))]), "the restart by model on 2 ranks");
    assert!(final_json(&on2) == reference, "a restart by model on 2 ranks ends elsewhere");
    restarted_in_part(&on2, &reference, &state, 2);
    // a free block thrown onto a layer of disks, bouncing off: the disks enter the
    // block's reach as it comes down (sent to every rank) and leave it as it goes
    let drop = write(&dir, "drop.toml", DROP);
    let reference = same_on_ranks(&dir, "drop", (&drop, 90, 4), &[2, 4]);
    // restarted on 4 ranks from a state of 2 written as the block touches the disks
    // (step 50): each rank builds the bodies near the block's reach at that state
    // (`FamilyKind::load_boxes` given the saved state), not every body
    let first = write(&dir, "drop50.toml", &DROP.replace("steps = 90", "steps = 50"));
    let half = dir.join("drop_half");
    ok(&mpirun(&[(2, args(&first, &half, &[]))]), "the drop's 50 steps on 2 ranks");
    let state = half.join("final.json");
    let on4 = dir.join("drop_restart4");
    ok(
        &mpirun(&[(4, args(&drop, &on4, &["--restart", state.to_str().unwrap()]))]),
        "the drop restarted on 4 ranks",
    );
    assert!(final_json(&on4) == reference, "the drop restarted on 4 ranks ends elsewhere");
    restarted_in_part(&on4, &reference, &state, 4);
    // 3D: spheres on a deformable block
    let lattice = ("origin = [0.2, 0.2, 0.42]", "origin = [0.2, 0.2, 0.36]");
    let s3 = write(&dir, "foundation3d.toml", &scene("foundation3d", (15, "nx = 2"), lattice));
    same_on_ranks(&dir, "3d", (&s3, 15, 2), &[2]);
}

/// A deformable block thrown down onto three layers of disks on a floor (it touches
/// them from step 45 to 59, then bounces off), decomposed by geometry in 4 cells.
const DROP: &str = r#"
[time]
step = 1e-3
theta = 0.5
steps = 90

[solver]
tolerance = 1e-5
max_sweeps = 20000

[detection]
alert = 0.005

[output]
every = 30
vtk = false

[decomposition]
nx = 4

[[materials]]
name = "soil"
density = 2000.0

[[materials]]
name = "stone"
density = 2500.0

[[laws]]
materials = ["soil", "stone"]
friction = 0.5

[[laws]]
materials = ["stone", "stone"]
friction = 0.3

[[bodies]]
name = "floor"
shape = "wall"
material = "stone"
position = [0.5, -0.01]
length = 1.2
thickness = 0.02
fixed = true

[[generate]]
kind = "square_lattice"
material = "stone"
radius = 0.02
origin = [0.05, 0.021]
nx = 22
ny = 3
spacing = 0.042

[[deformable]]
name = "block"
material = "soil"
young = 2e6
poisson = 0.3
velocity = [0.0, -1.5]
mesh = { rectangle = { origin = [0.3, 0.2], size = [0.4, 0.1], cells = [16, 4] } }
"#;
