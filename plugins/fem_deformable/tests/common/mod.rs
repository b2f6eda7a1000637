#![allow(dead_code)]
pub mod continuum;

use nscdd::registry::Registry;
use nscdd_fem_deformable::scene::{load_str, FeScene2};

pub fn registry() -> Registry {
    let mut r = Registry::new();
    r.add_plugin(&nscdd_fem_deformable::FemPlugin);
    r.add_plugin(&nscdd_rigid_disks::RigidDisks);
    r
}

pub fn scene(text: &str) -> FeScene2 {
    match load_str(text, "test.toml", &registry()) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    }
}

/// Σ r_n of the deformable contacts (N·s).
pub fn normal_impulse(s: &FeScene2) -> f64 {
    s.fe.contacts.r.iter().map(|r| r[0]).sum()
}

/// Mean of component `d` of the displacement over the nodes with coordinate
/// `axis` equal (to 1e-9) to `at` in the reference mesh.
pub fn mean_displacement(s: &FeScene2, body: usize, axis: usize, at: f64, d: usize) -> f64 {
    let b = &s.fe.bodies[body];
    let mut sum = 0.0;
    let mut n = 0;
    for k in 0..b.mesh.n_nodes() {
        if (b.mesh.x0[2 * k + axis] - at).abs() < 1e-9 {
            sum += b.u[2 * k + d];
            n += 1;
        }
    }
    sum / n as f64
}

/// Total energy of the deformable bodies: kinetic + elastic + load potential.
pub fn fe_energy(s: &FeScene2) -> f64 {
    s.fe.bodies
        .iter()
        .map(|b| b.kinetic_energy() + b.elastic_energy() + b.load_potential())
        .sum()
}
