//! The toy family glued to rigid disks by the framework's one NSCDD stage, run by
//! the framework's run loop: nothing of it is in the framework or the CLI.
//!
//! Scene: a fixed floor, disks of radius 0.1 m resting on it (ρ = 1000 kg/m², m_d
//! = 10π kg) and on top of each a point mass m_p = 0.5 kg, under g = 9.81 m/s².
//! At rest, the point–disk contact carries m_p g and the disk–floor contact
//! (m_d + m_p) g: impulses m_p g h and (m_d + m_p) g h per step.

use nscdd::dim::D2;
use nscdd::scene::Scene;
use nscdd_toy_family::PointMasses;
use std::path::Path;

mod common;
use common::*;

/// Runs the scene with the framework's run loop; its final.json.
fn run(text: &str, out: &Path, restart: Option<&Path>) -> String {
    let reg = registry();
    let mut s = Scene::<D2>::load_str(text, "toy.toml", &reg).unwrap_or_else(|e| panic!("{e}"));
    if let Some(state) = restart {
        nscdd::scene::restart_scene(&mut s, state).unwrap();
    }
    let sum = nscdd::run::run(&mut s, &reg, out, |_, _| {}).unwrap();
    assert_eq!(sum.unconverged_steps, 0);
    std::fs::read_to_string(out.join("final.json")).unwrap()
}

fn json(s: &str) -> serde_json::Value {
    serde_json::from_str(s).unwrap()
}

/// The points' state after `steps` steps, stepping the loaded scene directly.
fn step(text: &str, steps: usize) -> (Vec<[f64; 2]>, Vec<[f64; 2]>, Vec<f64>, usize) {
    let reg = registry();
    let mut s = Scene::<D2>::load_str(text, "toy.toml", &reg).unwrap();
    let one = nscdd::dd::DdConfig::default();
    let c = s.decomposition.clone().unwrap_or(one);
    let mut dd = c.solver_of();
    let mut interface = 0;
    for _ in 0..steps {
        let mut fams: Vec<&mut dyn nscdd::family::SceneFamily<D2>> = s.families.iter_mut().map(|f| &mut **f).collect();
        let (r, d) = nscdd::family::step(&mut s.world, &mut fams, Some(&mut dd)).unwrap();
        assert!(r.solve.converged);
        interface = interface.max(d.unwrap().interface_bodies);
    }
    let pm = s.families[0].as_any().downcast_ref::<PointMasses>().unwrap();
    (pm.x.clone(), s.world.bodies.pos.clone(), s.world.bodies.rot.clone(), interface)
}

#[test]
fn points_rest_on_disks_and_carry_their_weight() {
    let out = scratch("rest");
    let fin = json(&run(&scene(1, 300, ""), &out, None));
    let pc = &fin["families"]["point_masses"]["contacts"];
    assert_eq!(pc.as_array().unwrap().len(), 1, "{pc}");
    let rn = pc[0][2][0].as_f64().unwrap();
    assert!(
        (rn - MP * G * H).abs() < 1e-9 * MP * G * H.max(1.0),
        "point–disk r_n {rn}, m_p g h {}",
        MP * G * H
    );
    let md = 1000.0 * std::f64::consts::PI * 0.01;
    let floor = fin["contacts"][0]["r"][0].as_f64().unwrap();
    let expect = (md + MP) * G * H;
    assert!(
        (floor - expect).abs() < 1e-9 * expect.max(1.0),
        "disk–floor r_n {floor}, (m_d + m_p) g h {expect}"
    );
    let x = &fin["families"]["point_masses"]["x"][0];
    assert!((x[1].as_f64().unwrap() - 0.2).abs() < 1e-9, "the point rests on the disk: {x}");
    let hist = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(
        hist.lines().next().unwrap().ends_with(",kinetic_points"),
        "the family's history column"
    );
    std::fs::remove_dir_all(&out).ok();
}

/// By model on 2 × 1 cells (the points' contacts in subdomains of their own, glued
/// to the disks' through the disks), against one subdomain: the same state to the
/// solver's tolerance (1e-10 on the velocities' change over a sweep, over 100 steps
/// of 1 mm: positions agree to 1e-9 m); 1 and 2 threads bitwise.
#[test]
fn subdomains_by_model_agree_with_one_domain_and_threads_are_bitwise() {
    let (x1, p1, _, i1) = step(&scene(4, 100, ""), 100);
    assert_eq!(i1, 0, "one subdomain has no interface");
    let by = |threads: u32| scene(4, 100, &format!("[decomposition]\nby_model = true\nnx = 2\nthreads = {threads}\n"));
    let (x2, p2, o2, i2) = step(&by(1), 100);
    // the 4 disks, each shared by its disk–floor and its point–disk subdomain
    assert_eq!(i2, 4, "interface bodies");
    for (a, b) in x1.iter().zip(&x2) {
        assert!((a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9, "{a:?} {b:?}");
    }
    for (a, b) in p1.iter().zip(&p2) {
        assert!((0..2).all(|k| (a[k] - b[k]).abs() < 1e-9), "{a:?} {b:?}");
    }
    assert_eq!((x2, p2, o2, i2), step(&by(2), 100), "2 threads differ from 1");
}

/// Stopped at step 50 and restarted from its final.json (the family's and NSCDD's
/// states) to step 100: bitwise the uninterrupted run's final state.
#[test]
fn restart_continues_bitwise() {
    let out = scratch("restart");
    let dec = "[decomposition]\nby_model = true\nnx = 2\n[output]\nvtk = false\n";
    let whole = run(&scene(4, 100, dec), &out.join("whole"), None);
    run(&scene(4, 50, dec), &out.join("first"), None);
    let second = run(
        &scene(4, 100, dec),
        &out.join("second"),
        Some(&out.join("first").join("final.json")),
    );
    assert!(whole == second, "the restarted run ends elsewhere");
    std::fs::remove_dir_all(&out).ok();
}

/// A bad entry names its key and line; a section no plugin provides is refused.
#[test]
fn bad_entries_name_the_key() {
    let reg = registry();
    let bad = scene(1, 1, "").replace("mass = 0.5", "mass = -1.0");
    let e = Scene::<D2>::load_str(&bad, "toy.toml", &reg).err().expect("refused");
    assert_eq!(e.key, "point_masses[0].mass", "{e}");
    assert!(e.line.is_some(), "{e}");
    let e = Scene::<D2>::load_str(&scene(1, 1, ""), "toy.toml", &nscdd_rigid_disks::registry())
        .err()
        .expect("refused");
    assert_eq!(e.key, "point_masses", "{e}");
}
