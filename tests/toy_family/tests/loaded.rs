//! The toy family loaded at run time: the same crate built as a shared library
//! (`libnscdd_toy_family.so`), loaded by nscdd's loader, its family (scene section,
//! subdomain parts, sweeps, gluing, state) then behind the panic guard; a scene by
//! model on 2 × 1 subdomains with 2 threads gives byte for byte the `final.json` of
//! the family linked statically.
mod common;
use common::*;
use nscdd::dim::D2;
use nscdd::registry::Registry;
use nscdd::scene::Scene;

fn final_json(reg: &Registry, name: &str) -> String {
    let text = scene(
        4,
        100,
        "[decomposition]\nby_model = true\nnx = 2\nthreads = 2\n[output]\nvtk = false\n",
    );
    let mut s = Scene::<D2>::load_str(&text, "toy.toml", reg).unwrap_or_else(|e| panic!("{e}"));
    let out = scratch(name);
    let sum = nscdd::run::run(&mut s, reg, &out, |_, _| {}).unwrap();
    assert_eq!(sum.unconverged_steps, 0);
    let f = std::fs::read_to_string(out.join("final.json")).unwrap();
    let _ = std::fs::remove_dir_all(&out);
    f
}

#[test]
fn the_family_loaded_at_run_time_gives_the_linked_result_bitwise() {
    let mut loaded = nscdd_rigid_disks::registry();
    let l = nscdd::plugin::load(&nscdd::plugin::built_library("nscdd_toy_family").expect("built"), &mut loaded)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(l.plugins, vec!["toy_point_masses".to_string()]);
    assert!(loaded
        .plugin_contents()
        .iter()
        .any(|(p, c)| *p == "toy_point_masses" && c.iter().any(|x| x.contains("point_masses"))));
    let a = final_json(&registry(), "linked");
    let b = final_json(&loaded, "loaded");
    assert!(a.contains("point_masses"), "the family's state is in final.json");
    assert!(a == b, "final.json differs between the linked and the loaded family");
}
