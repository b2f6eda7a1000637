//! Makes `cargo test` build this crate's shared library with the features of the
//! command (cli/tests/plugins.rs loads it), and checks that it is there.

#[test]
fn the_shared_library_is_built() {
    assert!(
        nscdd::plugin::built_library("nscdd_plugin_panics").is_some(),
        "libnscdd_plugin_panics not built"
    );
}
