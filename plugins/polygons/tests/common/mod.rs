//! The polygons plugin as nscdd uses it: the shared library cargo built, loaded by
//! path with the framework's loader into a registry of the built-in disks plugin
//! (half-planes, walls, disks). The tests never call the crate's Rust items.
#![allow(dead_code)]

use nscdd::dim::D2;
use nscdd::registry::Registry;
use nscdd::scene::Scene;
use std::path::PathBuf;

/// The library cargo built beside this test.
pub fn library() -> PathBuf {
    nscdd::plugin::built_library("nscdd_polygons").expect("libnscdd_polygons not built")
}

/// The disks plugin's registry with the polygons library loaded at run time.
pub fn registry() -> Registry {
    let mut reg = nscdd_rigid_disks::registry();
    let lib = library();
    if let Err(e) = nscdd::plugin::load(&lib, &mut reg) {
        panic!("{}: {e}", lib.display());
    }
    reg
}

pub fn scene(text: &str) -> Scene<D2> {
    match Scene::<D2>::load_str(text, "test.toml", &registry()) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    }
}

/// A scene head: time step `h`, `steps`, θ = 1/2, tolerance 1e-6, one material
/// `stone` (2000 kg/m³) with friction `mu` on itself and on `ground`.
pub fn head(h: f64, steps: usize, mu: f64) -> String {
    format!(
        r#"[time]
step = {h}
theta = 0.5
steps = {steps}
[solver]
tolerance = 1e-6
max_sweeps = 20000
[detection]
alert = 0.002
[[materials]]
name = "stone"
density = 2000.0
[[materials]]
name = "ground"
density = 2000.0
[[laws]]
materials = ["stone", "stone"]
friction = {mu}
[[laws]]
materials = ["stone", "ground"]
friction = {mu}
[[laws]]
materials = ["ground", "ground"]
law = "none"
"#
    )
}

/// A polygon body of size [w, h] (a block) at `pos`, turned by `rot`.
pub fn block(pos: [f64; 2], size: [f64; 2], rot: f64, material: &str) -> String {
    format!(
        "[[bodies]]\nshape = \"polygon\"\nmaterial = \"{material}\"\nsize = [{}, {}]\nposition = [{}, {}]\nrotation = {rot}\n",
        size[0], size[1], pos[0], pos[1]
    )
}

/// A fixed half-plane through `pos` whose outward normal is (−sin θ, cos θ).
pub fn halfplane(pos: [f64; 2], rot: f64) -> String {
    format!(
        "[[bodies]]\nshape = \"halfplane\"\nmaterial = \"ground\"\nposition = [{}, {}]\nrotation = {rot}\nfixed = true\n",
        pos[0], pos[1]
    )
}

/// Normal impulse / h carried between bodies a and b, and the number of points.
pub fn carried(w: &nscdd::world::World2, a: u32, b: u32) -> (f64, usize) {
    let c = &w.contacts;
    let (mut f, mut n) = (0.0, 0);
    for k in 0..c.len() {
        let [i, j] = c.bodies[k];
        if (i, j) == (a, b) || (i, j) == (b, a) {
            f += c.r[k][0] / w.time.h;
            n += 1;
        }
    }
    (f, n)
}
