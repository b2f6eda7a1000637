//! Every scene in `examples/scenes` passes `nscdd check` (scenes with deformable
//! bodies when the binary has the `fem` feature); and `export-fc` refuses a state
//! with intact mortar joints, which a frictional-contact problem cannot express.

use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_nscdd");

#[test]
fn every_example_scene_checks() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/scenes");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        if (text.contains("[[deformable]]") || text.contains("[[continuum]]")) && !cfg!(feature = "fem") {
            continue;
        }
        let out = Command::new(BIN).arg("check").arg(&path).output().unwrap();
        assert!(
            out.status.success(),
            "{}: {}{}",
            path.display(),
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        n += 1;
    }
    assert!(n >= if cfg!(feature = "fem") { 10 } else { 7 }, "{n} scenes checked");
}

#[test]
fn export_fc_refuses_intact_mortar_joints() {
    let dir = std::env::temp_dir().join(format!("nscdd-examples-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("bonded.toml");
    let wall = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/scenes/wall.toml")).unwrap();
    let bonded = wall.replacen(
        "materials = [\"brick\", \"brick\"]\nfriction = 0.6",
        "materials = [\"brick\", \"brick\"]\nlaw = \"mohr_coulomb\"\nfriction = 0.6\ncohesion = 1e5",
        1,
    );
    assert_ne!(bonded, wall, "the wall's brick law");
    std::fs::write(&scene, bonded).unwrap();
    let out = Command::new(BIN)
        .args(["export-fc", "--steps", "2", "--out"])
        .arg(dir.join("p.json"))
        .arg(&scene)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("mortar joints"), "{err}");
    assert!(!dir.join("p.json").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
