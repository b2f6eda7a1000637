//! What the toy family's tests share: the scene (stacks of a disk and a point
//! mass on a floor) and the registries.
#![allow(dead_code)]

use nscdd::registry::Registry;
use nscdd_toy_family::PointMassesPlugin;
use std::path::PathBuf;

pub const H: f64 = 1e-3;
pub const G: f64 = 9.81;
pub const MP: f64 = 0.5;

/// The disks plugin's registry with the toy family linked.
pub fn registry() -> Registry {
    let mut r = nscdd_rigid_disks::registry();
    r.add_plugin(&PointMassesPlugin);
    r
}

/// `n` stacks 0.5 m apart; `extra`: more keys (a decomposition, outputs).
pub fn scene(n: usize, steps: u32, extra: &str) -> String {
    let mut s = format!(
        r#"
[time]
step = {H}
steps = {steps}
[solver]
tolerance = 1e-10
max_sweeps = 100000
[[materials]]
name = "m"
density = 1000.0
[[laws]]
materials = ["m", "m"]
friction = 0.5
[[bodies]]
shape = "wall"
material = "m"
position = [1.0, -0.005]
length = 4.0
thickness = 0.01
fixed = true
"#
    );
    for k in 0..n {
        let x = 0.5 * k as f64;
        s += &format!(
            "[[bodies]]\nshape = \"disk\"\nmaterial = \"m\"\nradius = 0.1\nposition = [{x}, 0.1]\n\
             [[point_masses]]\nmaterial = \"m\"\nmass = {MP}\nposition = [{x}, 0.2]\n"
        );
    }
    s + extra
}

pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("nscdd-toy-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}
