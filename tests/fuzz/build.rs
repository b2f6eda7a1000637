//! With the `fem` feature: an rpath to the libpython the deformable plugin was built
//! against (its build script exports the directory).
fn main() {
    println!("cargo:rerun-if-env-changed=DEP_NSCDD_PYTHON_LIBDIR");
    if let Ok(dir) = std::env::var("DEP_NSCDD_PYTHON_LIBDIR") {
        println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
