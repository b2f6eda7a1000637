//! Every example scene loads, and runs a few steps without diverging.

use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

#[test]
fn every_example_loads_and_steps() {
    let reg = nscdd_rigid_disks::registry();
    for s in nscdd_examples::SCENES {
        let mut scene = nscdd::scene::load(&root().join(s), &reg).unwrap_or_else(|e| panic!("{e}"));
        assert!(scene.world.bodies.len() > 1000, "{s}: a sample of more than 1000 bodies");
        for _ in 0..5 {
            let rep = scene.world.step().unwrap_or_else(|e| panic!("{s}: {e}"));
            assert!(rep.contacts > 0, "{s}: bodies in contact from the start");
        }
    }
}

#[test]
fn biaxial_history_has_the_biaxial_columns() {
    let reg = nscdd_rigid_disks::registry();
    let text = std::fs::read_to_string(root().join("examples/scenes/biaxial.toml")).unwrap();
    // a short run: compaction phase only
    let text = text.replace("duration = 1.3", "duration = 0.005");
    let mut scene = nscdd::scene::load_str(&text, "biaxial.toml", &reg).unwrap();
    let dir = std::env::temp_dir().join(format!("nscdd-biaxial-{}", std::process::id()));
    nscdd::run::run(&mut scene, &reg, &dir, |_, _| {}).unwrap();
    let hist = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let head: Vec<&str> = hist.lines().next().unwrap().split(',').collect();
    for col in ["eps1", "sin_phi", "solid_fraction", "top_y", "right_fx"] {
        assert!(head.contains(&col), "missing column {col}");
    }
    let last: Vec<f64> = hist.lines().last().unwrap().split(',').map(|x| x.parse().unwrap()).collect();
    let nu = last[head.iter().position(|c| *c == "solid_fraction").unwrap()];
    assert!((0.7..0.9).contains(&nu), "the deposit is dense: ν = {nu}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_3d_example_loads_and_steps() {
    let reg = nscdd_spheres::registry();
    for s in nscdd_examples::SCENES_3D {
        let text = std::fs::read_to_string(root().join(s)).unwrap();
        let mut scene = nscdd::scene::Scene3::load_str(&text, s, &reg).unwrap_or_else(|e| panic!("{e}"));
        assert!(scene.world.bodies.len() >= 1000, "{s}: a sample of at least 1000 bodies");
        for _ in 0..5 {
            scene.world.step().unwrap_or_else(|e| panic!("{s}: {e}"));
        }
    }
}
