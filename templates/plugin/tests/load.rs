//! The template as nscdd uses it: the shared library loaded at run time by the
//! framework's loader, a scene that names it, and a bead resting on a floor.

use std::path::PathBuf;

/// The library cargo built beside this test (target/PROFILE/deps/, or target/PROFILE/
/// after `cargo build`).
fn library() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    let name = format!(
        "{}nscdd_plugin_template{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    );
    [deps.join(&name), deps.parent().unwrap().join(&name)]
        .into_iter()
        .find(|p| p.exists())
        .unwrap_or_else(|| deps.join(&name))
}

#[test]
fn the_library_loads_and_a_bead_rests_on_a_floor() {
    let lib = library();
    assert!(lib.exists(), "{} not built", lib.display());
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
