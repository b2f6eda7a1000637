//! The overlap band of a `[[continuum]]` entry (`band = { normal, continuum,
//! discrete, grain_share }`): the continuum's weight α(x) across it, which weighs
//! the region's cells, the band grains' masses and their contacts' stiffness.

use crate::scene::entry_error;
use nscdd::family::EntryError;
use serde::Deserialize;

/// The overlap band: along the unit `normal`, the continuum's weight α is 1 at
/// s = n·x = `continuum`, 0 at s = `discrete`, linear between, clamped to [0, 1],
/// and inside the band at most 1 − `grain_share` (docs/CONTINUUM.md, weights).
#[derive(Deserialize, Debug, Clone, Copy)]
#[serde(deny_unknown_fields)]
pub struct Band {
    pub normal: [f64; 3],
    pub continuum: f64,
    pub discrete: f64,
    /// The least share of its mass (and of its contacts' stiffness) a band grain
    /// keeps; 0 (the default): the linear weight across the whole band.
    #[serde(default)]
    pub grain_share: f64,
}

impl Band {
    /// α(x), the continuum's weight.
    pub fn alpha(&self, x: &[f64]) -> f64 {
        let s: f64 = x.iter().zip(&self.normal).map(|(a, b)| a * b).sum();
        let a = ((self.discrete - s) / (self.discrete - self.continuum)).clamp(0.0, 1.0);
        // beyond the band the continuum alone; inside, the grains keep their share
        if a >= 1.0 {
            1.0
        } else {
            a.min(1.0 - self.grain_share)
        }
    }
}

pub(super) fn band_of(i: usize, e: &toml::Table, dim: usize) -> Result<Band, EntryError> {
    let at = |key: &str, message: String| entry_error(i, key, message);
    let v = e
        .get("band")
        .ok_or_else(|| at("band", "missing: `band = { normal, continuum, discrete }`".into()))?;
    let normal_len = v.get("normal").and_then(|n| n.as_array()).map(|a| a.len());
    if normal_len.is_some_and(|n| n != dim) {
        return Err(at("band", format!("`normal` needs {dim} numbers in {dim}D")));
    }
    let mut t = v.clone();
    if let Some(n) = t.get_mut("normal").and_then(|n| n.as_array_mut()) {
        n.resize(3, toml::Value::Float(0.0));
    }
    let mut b = Band::deserialize(t).map_err(|x| at("band", x.message().to_string()))?;
    let len = b.normal.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(len > 0.0 && len.is_finite()) {
        return Err(at("band", "`normal` must be a finite nonzero vector".into()));
    }
    b.normal = b.normal.map(|x| x / len);
    if !(0.0..1.0).contains(&b.grain_share) {
        return Err(at("band", format!("`grain_share` must lie in [0, 1), got {}", b.grain_share)));
    }
    if !(b.continuum.is_finite() && b.discrete.is_finite() && b.continuum != b.discrete) {
        return Err(at(
            "band",
            "`continuum` and `discrete` must be two different finite positions".into(),
        ));
    }
    Ok(b)
}
