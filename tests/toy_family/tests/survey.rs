//! On MPI ranks a scene is surveyed before each rank builds its part
//! (`nscdd::scene::part`). A body family that gives no load boxes (the toy family
//! keeps the default `FamilyKind::load_boxes`) cannot say which world bodies its load
//! reads, so its scene is loaded whole on every rank, as before the boxes existed:
//! linked, or loaded at run time behind the panic guard, which forwards the call.
mod common;
use common::*;
use nscdd::registry::Registry;

/// The survey of `text` (written to a scratch file): `Some` when the ranks build
/// their parts, `None` when the scene loads whole.
fn surveyed(reg: &Registry, text: &str, name: &str) -> bool {
    let dir = scratch(name);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("toy.toml");
    std::fs::write(&path, text).unwrap();
    let s = nscdd::scene::part::survey_any(&path, reg).unwrap_or_else(|e| panic!("{e}"));
    let _ = std::fs::remove_dir_all(&dir);
    s.is_some()
}

#[test]
fn a_family_without_load_boxes_loads_its_scene_whole_on_ranks() {
    let text = scene(4, 10, "[decomposition]\nnx = 2\n");
    assert!(!surveyed(&registry(), &text, "linked"), "the linked family");
    let mut loaded = nscdd_rigid_disks::registry();
    nscdd::plugin::load(&nscdd::plugin::built_library("nscdd_toy_family").expect("built"), &mut loaded).unwrap_or_else(|e| panic!("{e}"));
    assert!(!surveyed(&loaded, &text, "loaded"), "the family loaded at run time");
    // the same stacks without the point masses: surveyed, each rank builds its part
    let mut rigid = String::new();
    let mut skip = 0;
    for line in text.lines() {
        if line == "[[point_masses]]" {
            skip = 4;
        }
        if skip > 0 {
            skip -= 1;
        } else {
            rigid += line;
            rigid.push('\n');
        }
    }
    assert!(!rigid.contains("point_masses") && rigid.contains("shape = \"disk\""));
    assert!(surveyed(&registry(), &rigid, "rigid"), "a rigid scene");
}
