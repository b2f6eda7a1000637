//! Links the embedded Python: an rpath to the libpython pyo3 was built against (so
//! that the loader never picks another Python 3.x), and the virtualenv of that
//! Python, if it is one, as the default place of scikit-fem and meshio at run time.
fn main() {
    let cfg = pyo3_build_config::get();
    if let Some(dir) = cfg.lib_dir() {
        println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
        println!("cargo:rustc-env=NSCDD_PYTHON_LIBDIR={dir}");
        // DEP_NSCDD_PYTHON_LIBDIR for the build scripts of dependents
        println!("cargo:libdir={dir}");
    }
    println!("cargo:rerun-if-env-changed=PYO3_PYTHON");
    if let Ok(py) = std::env::var("PYO3_PYTHON") {
        let p = std::path::Path::new(&py);
        // <venv>/bin/python: the virtualenv holds pyvenv.cfg
        if let Some(venv) = p.parent().and_then(|b| b.parent()) {
            if venv.join("pyvenv.cfg").exists() {
                let abs = std::fs::canonicalize(venv).unwrap_or(venv.to_path_buf());
                println!("cargo:rustc-env=NSCDD_BUILD_VENV={}", abs.display());
            }
        }
    }
}
