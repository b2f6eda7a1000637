//! The compiler's version, part of the plugin interface's fingerprint
//! (`nscdd::plugin::RUSTC_VERSION`).
fn main() {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let v = std::process::Command::new(rustc)
        .arg("-V")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=NSCDD_RUSTC_VERSION={v}");
    println!("cargo:rerun-if-env-changed=RUSTC");
}
