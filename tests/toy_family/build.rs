//! Rebuilds this plugin at every cargo command. Cargo names a `cdylib` without a
//! hash (`target/release/deps/libNAME.so`): a build of the framework with other
//! features (another cargo command in the same `target/`) overwrites it while cargo
//! still counts this build as fresh, and nscdd would refuse the stale library
//! (docs/PLUGINS.md). A stamp that changes at every run keeps the library of the
//! last command.
fn main() {
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    println!("cargo:rustc-env=NSCDD_PLUGIN_BUILD_STAMP={now}");
    println!("cargo:rerun-if-changed=build.rs.stamp");
}
