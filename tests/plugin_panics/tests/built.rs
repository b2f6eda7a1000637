//! Makes `cargo test` build this crate's shared library with the features of the
//! command (cli/tests/plugins.rs loads it), and checks that it is there.

#[test]
fn the_shared_library_is_built() {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    let name = format!(
        "{}nscdd_plugin_panics{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    );
    assert!(
        deps.join(&name).exists() || deps.parent().unwrap().join(&name).exists(),
        "{name} not built"
    );
}
