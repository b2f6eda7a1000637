//! Helpers for plugins reading their own keys from a scene table, with messages that
//! name the key.

pub use crate::error::ParamError;

/// A finite number (integers accepted); `default` when the key is absent.
pub fn number(t: &toml::Table, key: &str, default: Option<f64>) -> Result<f64, ParamError> {
    match t.get(key) {
        None => default.ok_or_else(|| ParamError::new(key, "missing key")),
        Some(v) => {
            let x = v
                .as_float()
                .or_else(|| v.as_integer().map(|i| i as f64))
                .ok_or_else(|| ParamError::new(key, "must be a number"))?;
            if !x.is_finite() {
                return Err(ParamError::new(key, "must be finite"));
            }
            Ok(x)
        }
    }
}

/// A number > 0.
pub fn positive(t: &toml::Table, key: &str, default: Option<f64>) -> Result<f64, ParamError> {
    let x = number(t, key, default)?;
    if x <= 0.0 {
        return Err(ParamError::new(key, format!("must be > 0, got {x}")));
    }
    Ok(x)
}

/// A non-negative integer.
pub fn count(t: &toml::Table, key: &str, default: Option<u64>) -> Result<u64, ParamError> {
    match t.get(key) {
        None => default.ok_or_else(|| ParamError::new(key, "missing key")),
        Some(v) => match v.as_integer() {
            Some(i) if i >= 0 => Ok(i as u64),
            _ => Err(ParamError::new(key, "must be a non-negative integer")),
        },
    }
}

/// A boolean.
pub fn boolean(t: &toml::Table, key: &str, default: Option<bool>) -> Result<bool, ParamError> {
    match t.get(key) {
        None => default.ok_or_else(|| ParamError::new(key, "missing key")),
        Some(v) => v.as_bool().ok_or_else(|| ParamError::new(key, "must be true or false")),
    }
}

/// A string.
pub fn string<'a>(t: &'a toml::Table, key: &str, default: Option<&'a str>) -> Result<&'a str, ParamError> {
    match t.get(key) {
        None => default.ok_or_else(|| ParamError::new(key, "missing key")),
        Some(v) => v.as_str().ok_or_else(|| ParamError::new(key, "must be a string")),
    }
}

/// An array of `N` finite numbers.
pub fn array<const N: usize>(t: &toml::Table, key: &str, default: Option<[f64; N]>) -> Result<[f64; N], ParamError> {
    match t.get(key) {
        None => default.ok_or_else(|| ParamError::new(key, "missing key")),
        Some(v) => {
            let a = v
                .as_array()
                .filter(|a| a.len() == N)
                .ok_or_else(|| ParamError::new(key, format!("must be an array of {N} numbers")))?;
            let mut out = [0.0; N];
            for (o, x) in out.iter_mut().zip(a) {
                *o = x
                    .as_float()
                    .or_else(|| x.as_integer().map(|i| i as f64))
                    .filter(|f| f.is_finite())
                    .ok_or_else(|| ParamError::new(key, format!("must be an array of {N} finite numbers")))?;
            }
            Ok(out)
        }
    }
}

/// Rejects keys outside `allowed`.
pub fn only_keys(t: &toml::Table, allowed: &[&str]) -> Result<(), ParamError> {
    for k in t.keys() {
        if !allowed.contains(&k.as_str()) {
            return Err(ParamError::new(
                k.clone(),
                format!("unknown key `{k}`; expected one of: {}", allowed.join(", ")),
            ));
        }
    }
    Ok(())
}
