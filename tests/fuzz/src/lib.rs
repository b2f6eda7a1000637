//! # Fuzzing nscdd's inputs
//!
//! Targets ([`targets`]) take arbitrary bytes and must never panic, abort or hang:
//! every bad input is an `Err` with a message. A stable-Rust mutation fuzzer
//! ([`fuzz`]) runs them on mutants of a seed corpus (`tests/fuzz/corpus/TARGET/`,
//! from the examples): numbers set to 0, −1, ±1e308, NaN, inf, huge counts; lines
//! deleted or duplicated; truncations; byte flips; splices of two seeds.
//!
//! ```sh
//! cargo run --release -p nscdd-fuzz -- --seconds 60            # every target
//! cargo run --release -p nscdd-fuzz -- --seconds 600 scene3   # one target
//! ```
//!
//! A panic or a hang (an input running longer than the limit) is saved under
//! `target/fuzz-failures/` and the run exits 1.

#[cfg(feature = "hdf5")]
pub mod fclib;
pub mod mutate;

use nscdd::dim::{D2, D3};
use nscdd::fc::{CooMatrix, FcNorm, FcOptions, FcProblem};
use nscdd::registry::Registry;
use nscdd::scene::Scene;
use nscdd::solver::Method;

/// Memory a fuzzed scene may use: generators asked for more are refused.
const MAX_MEMORY: f64 = 2e9;

fn registry() -> Registry {
    let mut r = nscdd_rigid_disks::registry();
    r.add_plugin(&nscdd_spheres::SpheresPlugin);
    r.add_plugin(&nscdd_polyhedra::PolyhedraPlugin);
    r.set_max_memory(MAX_MEMORY);
    r
}

/// A 2D scene file.
pub fn scene2(data: &[u8]) {
    if let Ok(t) = std::str::from_utf8(data) {
        let _ = Scene::<D2>::load_str(t, "fuzz.toml", &registry());
    }
}

/// A 3D scene file (spheres, polyhedra, joints).
pub fn scene3(data: &[u8]) {
    if let Ok(t) = std::str::from_utf8(data) {
        let _ = Scene::<D3>::load_str(t, "fuzz.toml", &registry());
    }
}

/// The scene whose saved states the restart target reads.
pub const RESTART_SCENE: &str = "[time]\nstep = 1e-3\nsteps = 10\n[[materials]]\nname = \"m\"\ndensity = 1000.0\n[[laws]]\nmaterials = [\"m\", \"m\"]\nfriction = 0.3\n[[bodies]]\nshape = \"halfplane\"\nmaterial = \"m\"\nposition = [0.0, 0.0]\nfixed = true\n[[bodies]]\nshape = \"disk\"\nmaterial = \"m\"\nradius = 0.1\nposition = [0.0, 0.1]\n[[bodies]]\nshape = \"disk\"\nmaterial = \"m\"\nradius = 0.1\nposition = [0.0, 0.3]\n";

/// A saved state (final.json, checkpoint.json) read into [`RESTART_SCENE`].
pub fn restart(data: &[u8]) {
    if let Ok(t) = std::str::from_utf8(data) {
        let mut s = Scene::<D2>::load_str(RESTART_SCENE, "restart.toml", &registry()).expect("the fixed scene loads");
        if nscdd::scene::restart::restart_str(&mut s.world, t, "state.json").is_ok() {
            // a state that loads must also step
            let _ = s.world.step();
        }
    }
}

/// A frictional-contact problem in the JSON exchange format, solved when valid.
pub fn fc_json(data: &[u8]) {
    if let Ok(t) = std::str::from_utf8(data) {
        if let Ok(p) = FcProblem::parse(t, "fuzz.json") {
            solve_problem(&p);
        }
    }
}

pub(crate) fn solve_problem(p: &FcProblem) {
    // each method, and the over-relaxed sweeps (projected on the cones)
    for (method, relaxation) in [
        (Method::Nlgs, 1.0),
        (Method::Anderson, 1.0),
        (Method::Newton, 1.0),
        (Method::Nlgs, 1.5),
        (Method::Anderson, 1.5),
    ] {
        let _ = p.solve(&FcOptions {
            tol: 1e-8,
            max_sweeps: 50,
            check_every: 1,
            norm: FcNorm::Natural,
            method,
            relaxation,
        });
    }
}

/// `solve-fc` on arbitrary W, q, μ: the bytes give the dimension, the number of
/// contacts (≤ 6) and then the numbers (8 bytes each: any f64, NaN and infinities
/// included; a dense W). Invalid problems must be refused by `validate`, valid ones
/// solved.
pub fn solve_fc(data: &[u8]) {
    let Some((&head, rest)) = data.split_first() else { return };
    let dim = if head & 1 == 0 { 2 } else { 3 };
    let nc = (head >> 1) as usize % 7;
    let n = dim * nc;
    let mut x = rest.chunks(8).map(|c| {
        let mut b = [0u8; 8];
        b[..c.len()].copy_from_slice(c);
        f64::from_le_bytes(b)
    });
    let mut next = || x.next().unwrap_or(0.0);
    let mut trip = vec![];
    for i in 0..n {
        for j in 0..n {
            let v = next();
            if v != 0.0 {
                trip.push((i, j, v));
            }
        }
    }
    let q: Vec<f64> = (0..n).map(|_| next()).collect();
    let mu: Vec<f64> = (0..nc).map(|_| next()).collect();
    let p = FcProblem {
        dim,
        nc,
        w: CooMatrix::from_triplets(n, &trip),
        q,
        mu,
        meta: None,
    };
    if p.validate().is_ok() {
        solve_problem(&p);
    }
}

/// Memory a fuzzed deformable scene may use: a mesh of about 10⁴ nodes in 2D, 3·10³
/// in 3D (each built in well under a second).
#[cfg(feature = "fem")]
const MAX_FE_MEMORY: f64 = 1e8;

/// A scene with `[[deformable]]` bodies (2D or 3D: loaded as both), meshes built by
/// Python's scikit-fem and factored; a scene that loads is stepped twice.
#[cfg(feature = "fem")]
pub fn deformable(data: &[u8]) {
    let Ok(t) = std::str::from_utf8(data) else { return };
    let mut r = registry();
    r.add_plugin(&nscdd_fem_deformable::FemPlugin);
    r.set_max_memory(MAX_FE_MEMORY);
    if let Ok(mut s) = Scene::<D2>::load_str(t, "fuzz.toml", &r) {
        step_twice(&mut s);
    }
    if let Ok(mut s) = Scene::<D3>::load_str(t, "fuzz.toml", &r) {
        step_twice(&mut s);
    }
}

/// A scene loaded in part as each of 2 MPI ranks would (`nscdd::scene::part`): its
/// survey, then the rank's part, for ranks 0 and 1 (with the `fem` feature,
/// deformable bodies and continuum regions too: their load boxes).
pub fn part(data: &[u8]) {
    let Ok(t) = std::str::from_utf8(data) else { return };
    let dir = std::env::temp_dir().join(format!("nscdd-fuzz-part-{}", std::process::id()));
    let path = dir.join("fuzz.toml");
    if std::fs::create_dir_all(&dir).and_then(|()| std::fs::write(&path, t)).is_err() {
        return;
    }
    #[allow(unused_mut)]
    let mut r = registry();
    #[cfg(feature = "fem")]
    {
        r.add_plugin(&nscdd_fem_deformable::FemPlugin);
        r.set_max_memory(MAX_FE_MEMORY);
    }
    for me in 0..2 {
        if let Ok(Some(mut s)) = nscdd::scene::part::survey_any(&path, &r) {
            let _ = nscdd::scene::part::load_any_on(&mut s, &r, (2, me));
        }
    }
}

/// Two steps of a scene with its families (as the run loop makes its solver).
#[cfg(feature = "fem")]
fn step_twice<D: nscdd::dim::Dim>(s: &mut Scene<D>) {
    let decomposed = s.decomposition.is_some();
    let cfg = s
        .decomposition
        .clone()
        .or_else(|| nscdd::family::needs_nscdd(decomposed, &mut s.families).then(nscdd::dd::DdConfig::default));
    let mut dd = cfg.map(|c| c.solver_of());
    for _ in 0..2 {
        let mut fams: Vec<&mut dyn nscdd::family::SceneFamily<D>> = s.families.iter_mut().map(|f| &mut **f).collect();
        if nscdd::family::step(&mut s.world, &mut fams, dd.as_mut()).is_err() {
            break;
        }
    }
}

/// The fuzz targets by name (`deformable` with the `fem` feature, `fclib` with
/// `hdf5`), with the executions the corpus test gives each.
pub fn targets() -> Vec<(&'static str, fn(&[u8]))> {
    #[allow(unused_mut)]
    let mut t: Vec<(&'static str, fn(&[u8]))> = vec![
        ("scene2", scene2),
        ("scene3", scene3),
        ("restart", restart),
        ("fc_json", fc_json),
        ("solve_fc", solve_fc),
        ("part", part),
    ];
    #[cfg(feature = "fem")]
    t.push(("deformable", deformable));
    #[cfg(feature = "hdf5")]
    t.push(("fclib", fclib::fclib));
    t
}
