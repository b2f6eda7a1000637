//! The template as nscdd uses it: the shared library loaded at run time by the
//! framework's loader, a scene that names it, and a bead resting on a floor.

#[test]
fn the_library_loads_and_a_bead_rests_on_a_floor() {
    // the library cargo built beside this test
    let lib = nscdd::plugin::built_library("nscdd_plugin_template").expect("libnscdd_plugin_template not built");
    let scene = format!(
        r#"[time]
step = 1e-3
steps = 300
[[plugins]]
library = "{}"
[[materials]]
name = "m"
density = 1000.0
[[laws]]
materials = ["m", "m"]
friction = 0.3
[[bodies]]
shape = "halfplane"
material = "m"
position = [0.0, 0.0]
fixed = true
[[bodies]]
shape = "bead"
material = "m"
radius = 0.05
position = [0.0, 0.1]
"#,
        lib.display()
    );
    // the floor's half-plane is the built-in disks plugin's; the bead is ours
    let mut reg = nscdd_rigid_disks::registry();
    nscdd::plugin::load_for_scene(&scene, "bead.toml", &mut reg).unwrap();
    assert!(reg.shape_kinds::<nscdd::dim::D2>().contains(&"bead"));
    let mut s = nscdd::scene::Scene::<nscdd::dim::D2>::load_str(&scene, "bead.toml", &reg).unwrap();
    for _ in 0..300 {
        s.world.step().unwrap();
    }
    // it fell 5 cm and rests on the floor: centre at its radius, to the solver's accuracy
    let y = s.world.bodies.pos[1][1];
    assert!((y - 0.05).abs() < 1e-4, "the bead rests at y = {y}");
}
