//! The FCLIB target: an HDF5 problem file written from a JSON tree, read back by
//! [`nscdd::fc::fclib::read`] and solved when valid.
//!
//! The input is the file's tree as JSON: an object is a group, an array of integers
//! an `i64` dataset, an array of numbers an `f64` dataset, a number a one-value
//! dataset (`{"fclib_local": {"spacedim": 3, "W": {"m": 3, …, "p": [0, 1, 2, 3]}, …}}`):
//! mutating its text changes sizes, indices, pointers and values (0, −1, 1e308, NaN,
//! 2³²), deletes datasets or groups, so every check of the reader is met. (Mutating
//! the file's bytes would fuzz the HDF5 C library instead, whose corrupt-file
//! handling is outside nscdd.)

use serde_json::Value;

fn write(g: &hdf5::Group, tree: &serde_json::Map<String, Value>) -> hdf5::Result<()> {
    for (name, v) in tree {
        if name.is_empty() || name.contains('/') || name == "." {
            continue;
        }
        match v {
            Value::Object(m) => write(&g.create_group(name)?, m)?,
            Value::Number(_) => dataset(g, name, std::slice::from_ref(v))?,
            Value::Array(a) => dataset(g, name, a)?,
            _ => {}
        }
    }
    Ok(())
}

fn dataset(g: &hdf5::Group, name: &str, a: &[Value]) -> hdf5::Result<()> {
    if a.iter().all(|x| x.is_i64()) {
        let v: Vec<i64> = a.iter().filter_map(Value::as_i64).collect();
        g.new_dataset_builder().with_data(&v).create(name)?;
    } else {
        let v: Vec<f64> = a.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect();
        g.new_dataset_builder().with_data(&v).create(name)?;
    }
    Ok(())
}

/// The target (module docs).
pub fn fclib(data: &[u8]) {
    let Ok(Value::Object(tree)) = serde_json::from_slice::<Value>(data) else {
        return;
    };
    let path = std::env::temp_dir().join(format!("nscdd-fuzz-fclib-{}.h5", std::process::id()));
    let Ok(file) = hdf5::File::create(&path) else { return };
    let written = write(&file, &tree);
    drop(file);
    if written.is_ok() {
        if let Ok(p) = nscdd::fc::fclib::read(&path) {
            super::solve_problem(&p);
        }
    }
    let _ = std::fs::remove_file(&path);
}
