//! Contact laws: Signorini–Coulomb with Newton restitution and gap prediction.
//!
//! Over a step of length h, a contact with gap g (start of step), normal velocity
//! u_n⁻ at the start of the step and free normal velocity u_n,free is **active** when
//! its predicted gap closes:
//!
//! ```text
//! g_pred = g + h ((1 − θ) u_n⁻ + θ u_n,free) ≤ 0.
//! ```
//!
//! An active contact obeys Newton's impact law, `u_n⁺ + e min(u_n⁻, 0) ≥ 0 ⊥ r_n ≥ 0`
//! (e = 0: plastic impact, e = 1: elastic; with θ = ½ and e = 1 energy is kept). An
//! inactive contact may still be pushed closed by its neighbours during the solve; it
//! then obeys the position-level condition of the θ-method, `g⁺ ≥ 0`, i.e.
//! `u_n⁺ ≥ −(g + h (1 − θ) u_n⁻) / (h θ)`. Both are `u_n ≥ ū ⊥ r_n ≥ 0` with the
//! target ū computed by [`target_velocity`]; the tangential part is Coulomb's law with
//! the friction coefficient μ (see `dim::coulomb2`, `dim::coulomb3`).
//!
//! Laws are chosen per pair of materials. Built-in law kinds: `coulomb` (keys
//! `friction`, `restitution`), `frictionless` (key `restitution`), which takes the
//! cheaper μ = 0 path of the local solver, and `mohr_coulomb` (keys `friction`,
//! `cohesion`, `tensile_strength`, `bond_gap`): a mortar joint between 3D rigid
//! bodies that carries tension up to `tensile_strength` and shear up to
//! `cohesion + μ σ_n` (stresses, Pa) until it fails, then acts as `coulomb` with
//! e = 0 for ever (see `dim::joint`).

use crate::params::{number, only_keys};
use crate::params::ParamError;

/// Parameters of the law of one pair of materials.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactLaw {
    /// Friction coefficient μ ≥ 0.
    pub mu: f64,
    /// Newton restitution coefficient e ∈ [0, 1].
    pub e: f64,
    /// Cohesion c of a bonded joint (Pa; 0: no joint).
    #[serde(default)]
    pub cohesion: f64,
    /// Tensile strength σ_t of a bonded joint (Pa).
    #[serde(default)]
    pub tensile: f64,
    /// Contacts closer than this at the first step are bonded (m).
    #[serde(default)]
    pub bond_gap: f64,
}

impl ContactLaw {
    /// A Signorini–Coulomb law with friction μ and restitution e.
    pub fn coulomb(mu: f64, e: f64) -> ContactLaw {
        ContactLaw {
            mu,
            e,
            cohesion: 0.0,
            tensile: 0.0,
            bond_gap: 0.0,
        }
    }

    /// Whether contacts of this law can be bonded joints (`mohr_coulomb`).
    pub fn is_cohesive(&self) -> bool {
        self.cohesion > 0.0 || self.tensile > 0.0
    }
}

/// A law kind: its name and its parameter parser.
pub struct LawDef {
    pub name: &'static str,
    pub parse: fn(&toml::Table) -> Result<ContactLaw, ParamError>,
}

/// The target normal velocity ū of the law (see the module docs).
#[inline]
pub fn target_velocity(gap: f64, un_begin: f64, un_free: f64, h: f64, theta: f64, e: f64) -> f64 {
    let g_pred = gap + h * ((1.0 - theta) * un_begin + theta * un_free);
    if g_pred <= 0.0 {
        if un_begin < 0.0 {
            -e * un_begin
        } else {
            0.0
        }
    } else {
        -(gap + h * (1.0 - theta) * un_begin) / (h * theta)
    }
}

fn restitution(t: &toml::Table) -> Result<f64, ParamError> {
    let e = number(t, "restitution", Some(0.0))?;
    if !(0.0..=1.0).contains(&e) {
        return Err(ParamError::new("restitution", format!("must lie in [0, 1], got {e}")));
    }
    Ok(e)
}

fn parse_coulomb(t: &toml::Table) -> Result<ContactLaw, ParamError> {
    only_keys(t, &["friction", "restitution"])?;
    let mu = number(t, "friction", None)?;
    if mu < 0.0 {
        return Err(ParamError::new("friction", format!("μ must be ≥ 0, got {mu}")));
    }
    Ok(ContactLaw::coulomb(mu, restitution(t)?))
}

fn parse_frictionless(t: &toml::Table) -> Result<ContactLaw, ParamError> {
    only_keys(t, &["restitution"])?;
    Ok(ContactLaw::coulomb(0.0, restitution(t)?))
}

fn parse_mohr_coulomb(t: &toml::Table) -> Result<ContactLaw, ParamError> {
    only_keys(t, &["friction", "cohesion", "tensile_strength", "bond_gap"])?;
    let mu = number(t, "friction", None)?;
    if mu <= 0.0 {
        return Err(ParamError::new(
            "friction",
            format!("a mortar joint needs μ > 0 (its shear strength is c + μ σ_n), got {mu}"),
        ));
    }
    let cohesion = number(t, "cohesion", None)?;
    if cohesion < 0.0 {
        return Err(ParamError::new("cohesion", format!("must be ≥ 0 (Pa), got {cohesion}")));
    }
    // the tension cut-off cannot lie beyond the apex c/μ of the Mohr–Coulomb cone
    let apex = cohesion / mu;
    if !apex.is_finite() {
        return Err(ParamError::new(
            "friction",
            format!("too small for cohesion {cohesion}: c/μ overflows"),
        ));
    }
    let tensile = number(t, "tensile_strength", Some(apex))?;
    if !(0.0..=apex * (1.0 + 1e-12)).contains(&tensile) {
        return Err(ParamError::new(
            "tensile_strength",
            format!("must lie in [0, cohesion/friction = {apex}] (Pa), got {tensile}"),
        ));
    }
    if cohesion == 0.0 && tensile == 0.0 {
        return Err(ParamError::new(
            "cohesion",
            "a mortar joint needs cohesion > 0; use `coulomb` for dry joints",
        ));
    }
    let bond_gap = number(t, "bond_gap", Some(1e-6))?;
    if bond_gap < 0.0 {
        return Err(ParamError::new("bond_gap", format!("must be ≥ 0 (m), got {bond_gap}")));
    }
    Ok(ContactLaw {
        mu,
        e: 0.0,
        cohesion,
        tensile: tensile.min(apex),
        bond_gap,
    })
}

/// The framework's own laws: `coulomb`, `frictionless`, `mohr_coulomb`.
pub(crate) fn builtin() -> [LawDef; 3] {
    [
        LawDef {
            name: "coulomb",
            parse: parse_coulomb,
        },
        LawDef {
            name: "frictionless",
            parse: parse_frictionless,
        },
        LawDef {
            name: "mohr_coulomb",
            parse: parse_mohr_coulomb,
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn targets() {
        // approaching ball, predicted to close: Newton
        assert_eq!(target_velocity(1e-4, -1.0, -1.0, 1e-3, 0.5, 0.5), 0.5);
        // far away: position condition, very negative
        assert!(target_velocity(1.0, -1.0, -1.0, 1e-3, 0.5, 0.5) < -100.0);
        // resting
        assert_eq!(target_velocity(0.0, 0.0, -1e-2, 1e-3, 0.5, 0.0), 0.0);
    }
}
