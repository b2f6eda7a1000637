//! A region's initial stress σ0 (`initial_stress`, docs/CONTINUUM.md): the same in
//! every cell, or the geostatic stress of a ground at rest under its own weight and
//! a surcharge, so that a foundation does not first sag and ring under the weight
//! it carries.
//!
//! Geostatic, with ĝ = g/|g| and the depth d of a cell's centroid below the region's
//! highest node along −ĝ:
//!
//! ```text
//! σ_v = −(q + ρ|g| d),   σ0 = σ_v ĝ⊗ĝ + K0 σ_v (I − ĝ⊗ĝ)
//! ```
//!
//! q the surcharge on the region's top (the weight of what rests on it a unit area,
//! Pa), ρ the region's density, K0 the earth pressure coefficient at rest (default
//! ν/(1 − ν), the elastic one under lateral confinement). In plane strain σ_zz is
//! ν(σ_xx + σ_yy), as for a uniform σ0. ρ|g|d is the medium's whole weight: in the
//! overlap band the continuum carries its share α of it (its stress is weighted by
//! α), the band grains the rest through their ties. The depth is measured from the
//! highest node: the field balances the region's weight when its top is flat and
//! level (a sloped or stepped top is left with unbalanced tractions on its lower
//! faces, which the first steps take up).

use super::scene::CellFrame;
use crate::mesh::Mesh;
use crate::scene::entry_error;
use nscdd::family::EntryError;

/// `initial_stress` as given.
#[derive(Clone, Debug, PartialEq)]
pub enum InitialStress {
    /// `[σxx, σyy, σxy]` (3D `[σxx, σyy, σzz, σxy, σyz, σxz]`), Pa, tension
    /// positive, in every cell (2D: zz NaN, set from ν by the caller).
    Uniform([[f64; 3]; 3]),
    /// `{ k0 = K0, surcharge = q }` (module docs); `k0` None: ν/(1 − ν).
    Geostatic { k0: Option<f64>, surcharge: f64 },
}

const KEY: &str = "initial_stress";
const NO_GRAVITY: &str = "a geostatic initial stress needs gravity (the scene's `gravity` is zero)";

/// Entry `i`'s `initial_stress`, if any: an array (uniform) or a table (geostatic,
/// which needs `gravity`).
pub fn of(i: usize, e: &toml::Table, dim: usize, gravity: &[f64]) -> Result<Option<InitialStress>, EntryError> {
    let Some(v) = e.get(KEY) else { return Ok(None) };
    if let Some(t) = v.as_table() {
        if !gravity.iter().any(|&x| x != 0.0) {
            return Err(entry_error(i, KEY, NO_GRAVITY));
        }
        return geostatic_of(i, t).map(Some);
    }
    let n = if dim == 2 { 3 } else { 6 };
    let what = if dim == 2 { "[xx, yy, xy]" } else { "[xx, yy, zz, xy, yz, xz]" };
    let s: Vec<f64> = v
        .as_array()
        .map(|a| a.iter().filter_map(number).collect())
        .filter(|a: &Vec<f64>| a.len() == n && a.len() == v.as_array().map_or(0, |b| b.len()) && a.iter().all(|x| x.is_finite()))
        .ok_or_else(|| {
            let m = format!("{n} numbers {what} (Pa, tension positive), or a geostatic stress {{ k0 = K0, surcharge = q }}");
            entry_error(i, KEY, m)
        })?;
    let t = match dim {
        2 => [[s[0], s[2], 0.0], [s[2], s[1], 0.0], [0.0, 0.0, f64::NAN]],
        _ => [[s[0], s[3], s[5]], [s[3], s[1], s[4]], [s[5], s[4], s[2]]],
    };
    Ok(Some(InitialStress::Uniform(t)))
}

fn number(x: &toml::Value) -> Option<f64> {
    x.as_float().or(x.as_integer().map(|k| k as f64))
}

fn geostatic_of(i: usize, t: &toml::Table) -> Result<InitialStress, EntryError> {
    let (mut k0, mut surcharge) = (None, 0.0);
    for (k, v) in t {
        let x = number(v).filter(|x| x.is_finite());
        let m = match (k.as_str(), x) {
            ("k0", Some(x)) if x >= 0.0 => {
                k0 = Some(x);
                continue;
            }
            ("surcharge", Some(x)) if x >= 0.0 => {
                surcharge = x;
                continue;
            }
            ("k0", _) => format!("`k0`: the earth pressure coefficient at rest K0 ≥ 0, got {v}"),
            ("surcharge", _) => format!("`surcharge`: a pressure ≥ 0 on the region's top (Pa), got {v}"),
            _ => format!("unknown key `{k}` of a geostatic initial stress (`k0`, `surcharge`)"),
        };
        return Err(entry_error(i, KEY, m));
    }
    Ok(InitialStress::Geostatic { k0, surcharge })
}

/// σ0 of every cell of `m` (`frames`: its cells' centroids), for a region of
/// density `rho` and Poisson's ratio `nu` under `gravity`. 2D: σ_zz NaN (the
/// caller's plane strain). Err: a geostatic stress without gravity.
pub fn per_cell(
    s: &InitialStress,
    m: &Mesh,
    frames: &[CellFrame],
    rho: f64,
    nu: f64,
    gravity: &[f64],
) -> Result<Vec<[[f64; 3]; 3]>, String> {
    let (k0, q) = match *s {
        InitialStress::Uniform(t) => return Ok(vec![t; frames.len()]),
        InitialStress::Geostatic { k0, surcharge } => (k0.unwrap_or(nu / (1.0 - nu)), surcharge),
    };
    let d = m.dim;
    let g = gravity[..d].iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(g > 0.0) {
        return Err(NO_GRAVITY.into());
    }
    let up: Vec<f64> = gravity[..d].iter().map(|x| -x / g).collect();
    let height = |x: &[f64]| x.iter().zip(&up).map(|(a, b)| a * b).sum::<f64>();
    let top = (0..m.n_nodes()).map(|k| height(m.node(k))).fold(f64::NEG_INFINITY, f64::max);
    let out = frames
        .iter()
        .map(|(_, c)| {
            let sv = -(q + rho * g * (top - height(&c[..d])));
            let mut t: [[f64; 3]; 3] = std::array::from_fn(|a| {
                std::array::from_fn(|b| {
                    let (ua, ub) = (up.get(a).copied().unwrap_or(0.0), up.get(b).copied().unwrap_or(0.0));
                    let delta = if a == b { 1.0 } else { 0.0 };
                    sv * ua * ub + k0 * sv * (delta - ua * ub)
                })
            });
            if d == 2 {
                t[2][2] = f64::NAN;
            }
            t
        })
        .collect::<Vec<_>>();
    if out.iter().flatten().flatten().any(|x| x.is_infinite()) {
        return Err(format!(
            "the geostatic stress (K0 = {k0}, surcharge {q} Pa) is too large to hold in numbers"
        ));
    }
    Ok(out)
}
