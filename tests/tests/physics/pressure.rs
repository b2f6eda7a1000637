//! A pressure drive on a wall of a 2D box sample: a square lattice of 4 × 4 disks
//! (radius 1 cm) in a box whose right wall is pushed by σ = 10 kPa over the box's
//! current height H (a force σ H per unit depth, along −x). At rest the wall is in
//! equilibrium, so the contact force the disks exert on it is σ H; measured after
//! the lattice has settled (plastic impacts, no gravity).

use super::common::*;

const SIGMA: f64 = 1e4;

fn box_scene(drive: &str) -> String {
    format!(
        r#"
gravity = [0.0, 0.0]
[time]
step = 1e-4
steps = 3000
[solver]
tolerance = 1e-6
max_sweeps = 5000
[output]
box = {{ left = "left", right = "right", bottom = "bottom", top = "top" }}
[[materials]]
name = "m"
density = 1000.0
[[laws]]
materials = ["m", "m"]
law = "frictionless"
[[bodies]]
name = "left"
shape = "wall"
material = "m"
position = [-0.005, 0.04]
rotation = 1.5707963267948966
length = 0.2
thickness = 0.01
fixed = true
[[bodies]]
name = "bottom"
shape = "wall"
material = "m"
position = [0.04, -0.005]
length = 0.2
thickness = 0.01
fixed = true
[[bodies]]
name = "top"
shape = "wall"
material = "m"
position = [0.04, 0.085]
length = 0.2
thickness = 0.01
fixed = true
[[bodies]]
name = "right"
shape = "wall"
material = "m"
position = [0.0852, 0.04]
rotation = 1.5707963267948966
length = 0.06
thickness = 0.01
drive = {{ {drive} }}
[[generate]]
kind = "square_lattice"
material = "m"
nx = 4
ny = 4
radius = 0.01
origin = [0.01, 0.01]
"#
    )
}

#[test]
fn pressure_on_a_2d_box_wall_balances_the_grains() {
    let mut s = scene(&box_scene(&format!(
        "x = {{ pressure = {SIGMA} }}, y = {{ velocity = 0.0 }}, rot = {{ velocity = 0.0 }}"
    )));
    steps(&mut s, 3000);
    let w = &s.world;
    let e = w.box_extent().unwrap();
    let height = e.max[1] - e.min[1];
    let right = w.names.iter().position(|n| n.as_deref() == Some("right")).unwrap();
    let fx = w.reaction[right][0] / w.time.h;
    // the disks push the wall towards +x with σ H; the wall is at rest (plastic
    // impacts), so the balance holds to the solver's tolerance (1e-6)
    assert_rel("wall force / (σ H)", fx / (SIGMA * height), 1.0, 1e-5);
    // the wall rests on the lattice: 4 disks of diameter 2 cm
    assert_rel("box width", e.max[0] - e.min[0], 0.08, 1e-3);
}

#[test]
fn a_pressure_drive_off_a_wall_axis_is_refused() {
    // the right wall pushed along y, not along its own axis
    let text = box_scene(&format!("y = {{ pressure = {SIGMA} }}"));
    let err = match nscdd::scene::load_str(&text, "p.toml", &nscdd_rigid_disks::registry()) {
        Ok(_) => panic!("accepted a pressure drive on a body that is not a wall of the box"),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("pressure drive needs the body to be a wall"), "{err}");
}
