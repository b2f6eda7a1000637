//! Python values as TOML: a scene built from dicts and lists is written as the TOML
//! text the scene loader reads, so that it is checked by the same code, with the
//! same messages, as a scene file.

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// A Python value as a TOML value: dict (str keys) → table, list/tuple (and any
/// object with `tolist()`, such as a NumPy array) → array, bool, int, float, str.
/// `path` names the value in an error.
pub fn value(v: &Bound<'_, PyAny>, path: &str) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(v.extract()?));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        return table(d, path).map(toml::Value::Table);
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut out = vec![];
        for (i, x) in v.try_iter()?.enumerate() {
            out.push(value(&x?, &format!("{path}[{i}]"))?);
        }
        return Ok(toml::Value::Array(out));
    }
    if v.hasattr("tolist")? {
        return value(&v.call_method0("tolist")?, path);
    }
    // NumPy scalars and other numbers
    if let Ok(x) = v.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    Err(PyTypeError::new_err(format!(
        "scene key `{path}`: a {} cannot be a scene value (dict, list, str, bool, int or float)",
        v.get_type().name()?
    )))
}

/// A dict with string keys as a TOML table.
pub fn table(d: &Bound<'_, PyDict>, path: &str) -> PyResult<toml::Table> {
    let mut t = toml::Table::new();
    for (k, v) in d.iter() {
        let key: String = k
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("scene keys are strings; `{path}` has the key {k}")))?;
        let here = if path.is_empty() { key.clone() } else { format!("{path}.{key}") };
        // None: the key is left out (its default)
        if v.is_none() {
            continue;
        }
        t.insert(key, value(&v, &here)?);
    }
    Ok(t)
}
