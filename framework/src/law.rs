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
//! e = 0 for ever (see `dim::joint`), and `compliant` (keys `stiffness`, `damping`,
//! `friction`): a normal spring and dashpot, solved implicitly as a normal
//! compliance c added to W_nn ([`Compliant`]).
//!
//! A law is a registered type: a [`LawDef`] (name and parameter parser, added by
//! [`crate::registry::Registry::add_law`]) makes, for each pair of materials of a
//! scene, a value implementing [`Law`]. At each step's contact build the engine
//! hands every law the contacts of its pairs in one batch ([`Law::contacts`]: one
//! call per pair of materials, none per contact) and gets back what the local
//! solver needs of each contact: the target ū, the friction coefficient μ and the
//! bonded joint, if any. The solver's kernels (the exact Signorini–Coulomb
//! solvers and the joint solver of `dim`) are shared by every law; a law whose
//! local problem is of another kind needs a kernel in `dim` as well.
//!
//! ```
//! use nscdd::dim::joint::Joint;
//! use nscdd::law::{Law, LawDef, LawInput, LawStep};
//! use nscdd::model::Target;
//! /// Friction growing with the impact speed (a toy).
//! #[derive(Debug)]
//! struct SpeedFriction { mu0: f64, k: f64 }
//! impl Law for SpeedFriction {
//!     fn contacts(&self, step: &LawStep, inputs: &[LawInput], target: &mut [Target], _joint: &mut [Joint]) {
//!         for (c, t) in inputs.iter().zip(target) {
//!             let u_target = nscdd::law::target_velocity(c.gap, c.un_begin, c.un_free, step.h, step.theta, 0.0);
//!             *t = Target { u_target, mu: self.mu0 + self.k * c.un_begin.abs() };
//!         }
//!     }
//! }
//! let mut reg = nscdd::registry::Registry::new();
//! reg.add_law(LawDef {
//!     name: "speed_friction",
//!     parse: |t| {
//!         nscdd::params::only_keys(t, &["mu0", "k"])?;
//!         let mu0 = nscdd::params::number(t, "mu0", None)?;
//!         let k = nscdd::params::number(t, "k", Some(0.0))?;
//!         Ok(std::sync::Arc::new(SpeedFriction { mu0, k }))
//!     },
//! });
//! assert!(reg.law_names().contains(&"speed_friction"));
//! ```

use crate::dim::joint::Joint;
use crate::model::Target;
use crate::params::ParamError;
use crate::params::{number, only_keys};
use std::sync::Arc;

/// What a law sees of one contact when the step's contact set is built.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LawInput {
    /// Gap g at the start of the step (m).
    pub gap: f64,
    /// Normal relative velocity u_n⁻ at the start of the step.
    pub un_begin: f64,
    /// Free normal relative velocity u_n,free.
    pub un_free: f64,
    /// Area (3D) or length (2D) of a face-to-face contact; 0 for a point contact.
    pub area: f64,
    /// A contact continued from the last step: whether it was bonded then;
    /// `None` for a new contact.
    pub was_bonded: Option<bool>,
}

/// The step's constants a law reads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LawStep {
    /// Step h (s).
    pub h: f64,
    /// θ of the θ-method.
    pub theta: f64,
    /// The scene's first step (bonds are made then).
    pub first: bool,
}

/// What the local solver gets of one contact: ū and μ, and its bonded joint
/// (`Joint::default()`: none).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LawOutput {
    pub target: Target,
    pub joint: Joint,
}

/// A contact law between one pair of materials, with its parameters (module
/// docs). Implementations are plain data: the engine calls them once per pair of
/// materials and step with every contact of the pair.
pub trait Law: Send + Sync + std::fmt::Debug {
    /// ū and μ (`target[k]`) and the joint (`joint[k]`) of each contact
    /// `inputs[k]`; both hold defaults on entry (no joint).
    fn contacts(&self, step: &LawStep, inputs: &[LawInput], target: &mut [Target], joint: &mut [Joint]);
    /// [`Law::contacts`] for one contact (outside the time loop's hot paths).
    fn contact(&self, step: &LawStep, input: &LawInput) -> LawOutput {
        let (mut t, mut j) = ([Target::default()], [Joint::default()]);
        self.contacts(step, std::slice::from_ref(input), &mut t, &mut j);
        LawOutput { target: t[0], joint: j[0] }
    }
    /// Whether contacts may be bonded joints, which need detectors that report
    /// contact areas.
    fn bonds(&self) -> bool {
        false
    }
    /// The normal compliance c ≥ 0 of this law's contacts over a step of `step`:
    /// their normal law is `u_n + c r_n ≥ ū ⊥ r_n ≥ 0` (0: rigid, the default).
    fn compliance(&self, _step: &LawStep) -> f64 {
        0.0
    }
}

/// A law kind: its name and the parser of its parameters (the keys of a
/// `[[laws]]` entry other than `materials` and `law`).
pub struct LawDef {
    pub name: &'static str,
    pub parse: fn(&toml::Table) -> Result<Arc<dyn Law>, ParamError>,
}

/// Signorini–Coulomb with Newton restitution (laws `coulomb` and, μ = 0,
/// `frictionless`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coulomb {
    /// Friction coefficient μ ≥ 0.
    pub mu: f64,
    /// Newton restitution coefficient e ∈ [0, 1].
    pub e: f64,
}

impl Law for Coulomb {
    fn contacts(&self, step: &LawStep, inputs: &[LawInput], target: &mut [Target], _joint: &mut [Joint]) {
        for (c, t) in inputs.iter().zip(target) {
            *t = Target {
                u_target: target_velocity(c.gap, c.un_begin, c.un_free, step.h, step.theta, self.e),
                mu: self.mu,
            };
        }
    }
}

/// A compliant contact (law `compliant`): a linear spring of stiffness k and a
/// dashpot d in the normal direction, Coulomb friction μ (LMGC90's
/// `ELASTIC_REPELL_CLB` with a dashpot). The normal impulse over the step is
///
/// ```text
/// r_n = h max(0, −k g_θ − d u_n⁺),   g_θ = (1 − θ) g + θ g⁺ = g + hθ((1 − θ) u_n⁻ + θ u_n⁺),
/// ```
///
/// the spring taken at the θ-point of the gap (θ = ½: the midpoint rule, which
/// keeps the energy of an undamped contact). Solved for u_n⁺ it is
/// `u_n + c r_n ≥ ū ⊥ r_n ≥ 0` with
///
/// ```text
/// c = 1 / (h (hθ² k + d)),   ū = −k (g + hθ(1 − θ) u_n⁻) / (hθ² k + d).
/// ```
///
/// A resting contact under a load F sinks by F/k; two bodies of reduced mass m
/// stay in contact for π √(m/k) (d = 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compliant {
    /// Friction coefficient μ ≥ 0.
    pub mu: f64,
    /// Normal stiffness k > 0 (N/m; in 2D per unit thickness, Pa).
    pub k: f64,
    /// Normal damping d ≥ 0 (N·s/m; in 2D per unit thickness).
    pub d: f64,
}

impl Law for Compliant {
    fn contacts(&self, step: &LawStep, inputs: &[LawInput], target: &mut [Target], _joint: &mut [Joint]) {
        let (h, th) = (step.h, step.theta);
        let s = h * th * th * self.k + self.d;
        for (c, t) in inputs.iter().zip(target) {
            *t = Target {
                u_target: -self.k * (c.gap + h * th * (1.0 - th) * c.un_begin) / s,
                mu: self.mu,
            };
        }
    }
    fn compliance(&self, step: &LawStep) -> f64 {
        1.0 / (step.h * (step.h * step.theta * step.theta * self.k + self.d))
    }
}

/// A mortar joint (law `mohr_coulomb`): contacts closer than `bond_gap` at the
/// first step are bonded, with tensile strength σ_t and shear strength c + μ σ_n
/// over their area, until they fail; then Coulomb with e = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MohrCoulomb {
    pub mu: f64,
    /// Cohesion c (Pa).
    pub cohesion: f64,
    /// Tensile strength σ_t (Pa), at most c/μ.
    pub tensile: f64,
    /// Contacts closer than this at the first step are bonded (m).
    pub bond_gap: f64,
}

impl Law for MohrCoulomb {
    fn contacts(&self, step: &LawStep, inputs: &[LawInput], target: &mut [Target], joint: &mut [Joint]) {
        for ((c, t), j) in inputs.iter().zip(target).zip(joint) {
            *t = Target {
                u_target: target_velocity(c.gap, c.un_begin, c.un_free, step.h, step.theta, 0.0),
                mu: self.mu,
            };
            // bonds are made at the first step only
            let bonded = c.was_bonded.unwrap_or(step.first && c.gap <= self.bond_gap);
            if bonded && c.area > 0.0 {
                *j = Joint::of(self.cohesion, self.tensile, self.mu, c.area, step.h);
            }
        }
    }
    fn bonds(&self) -> bool {
        true
    }
}

/// A step's contacts and their pairs of materials, for one call of each law
/// (buffers reused from step to step).
#[derive(Default)]
pub(crate) struct LawBatches {
    /// In contact order.
    inputs: Vec<LawInput>,
    slot: Vec<u32>,
    /// The contacts of each pair of materials, `idx[start[s]..start[s + 1]]`.
    start: Vec<u32>,
    idx: Vec<u32>,
    /// The next free place of each pair in `idx` while it is filled.
    next: Vec<u32>,
    /// One pair's inputs and outputs.
    g_in: Vec<LawInput>,
    g_target: Vec<Target>,
    g_joint: Vec<Joint>,
}

impl LawBatches {
    pub fn clear(&mut self) {
        self.inputs.clear();
        self.slot.clear();
    }
    /// The next contact, of the pair of materials `slot`.
    #[inline]
    pub fn push(&mut self, slot: usize, input: LawInput) {
        self.inputs.push(input);
        self.slot.push(slot as u32);
    }
    /// Every law on its contacts, one call per pair of materials, into `target`
    /// and `joint` (contact order).
    pub fn run(&mut self, laws: &[Option<Arc<dyn Law>>], step: &LawStep, target: &mut Vec<Target>, joint: &mut Vec<Joint>) {
        let n = self.inputs.len();
        target.clear();
        target.resize(n, Target::default());
        joint.clear();
        joint.resize(n, Joint::default());
        let Some(&s0) = self.slot.first() else { return };
        if self.slot.iter().all(|&s| s == s0) {
            // one pair of materials: no gathering
            if let Some(law) = &laws[s0 as usize] {
                law.contacts(step, &self.inputs, target, joint);
            }
            return;
        }
        // the contacts by pair (a counting sort, contact order kept within a pair)
        self.start.clear();
        self.start.resize(laws.len() + 1, 0);
        for &s in &self.slot {
            self.start[s as usize + 1] += 1;
        }
        for k in 0..laws.len() {
            self.start[k + 1] += self.start[k];
        }
        self.idx.resize(n, 0);
        self.next.clear();
        self.next.extend_from_slice(&self.start);
        for (a, &s) in self.slot.iter().enumerate() {
            self.idx[self.next[s as usize] as usize] = a as u32;
            self.next[s as usize] += 1;
        }
        for (s, law) in laws.iter().enumerate() {
            let (Some(law), lo, hi) = (law, self.start[s] as usize, self.start[s + 1] as usize) else {
                continue;
            };
            if lo == hi {
                continue;
            }
            let idx = &self.idx[lo..hi];
            self.g_in.clear();
            self.g_in.extend(idx.iter().map(|&a| self.inputs[a as usize]));
            self.g_target.clear();
            self.g_target.resize(idx.len(), Target::default());
            self.g_joint.clear();
            self.g_joint.resize(idx.len(), Joint::default());
            law.contacts(step, &self.g_in, &mut self.g_target, &mut self.g_joint);
            for (k, &a) in idx.iter().enumerate() {
                target[a as usize] = self.g_target[k];
                joint[a as usize] = self.g_joint[k];
            }
        }
    }
}

impl LawBatches {
    /// Each contact's compliance ([`Law::compliance`], one call per law) into
    /// `out` (contact order) and true; false and `out` empty when no law is
    /// compliant.
    pub fn compliance(&self, laws: &[Option<Arc<dyn Law>>], step: &LawStep, out: &mut Vec<f64>) -> bool {
        out.clear();
        // a law's c that is not a finite number ≥ 0 (a plugin's bug) counts as rigid
        let of = |l: &Arc<dyn Law>| Some(l.compliance(step)).filter(|c| c.is_finite() && *c > 0.0).unwrap_or(0.0);
        if laws.iter().all(|l| l.as_ref().is_none_or(|l| of(l) == 0.0)) {
            return false;
        }
        let per: Vec<f64> = laws.iter().map(|l| l.as_ref().map_or(0.0, of)).collect();
        out.extend(self.slot.iter().map(|&s| per[s as usize]));
        true
    }
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

fn parse_coulomb(t: &toml::Table) -> Result<Arc<dyn Law>, ParamError> {
    only_keys(t, &["friction", "restitution"])?;
    let mu = number(t, "friction", None)?;
    if mu < 0.0 {
        return Err(ParamError::new("friction", format!("μ must be ≥ 0, got {mu}")));
    }
    Ok(Arc::new(Coulomb { mu, e: restitution(t)? }))
}

fn parse_frictionless(t: &toml::Table) -> Result<Arc<dyn Law>, ParamError> {
    only_keys(t, &["restitution"])?;
    Ok(Arc::new(Coulomb {
        mu: 0.0,
        e: restitution(t)?,
    }))
}

fn parse_compliant(t: &toml::Table) -> Result<Arc<dyn Law>, ParamError> {
    only_keys(t, &["friction", "stiffness", "damping"])?;
    let mu = number(t, "friction", Some(0.0))?;
    if mu < 0.0 {
        return Err(ParamError::new("friction", format!("μ must be ≥ 0, got {mu}")));
    }
    let k = number(t, "stiffness", None)?;
    if !(k > 0.0 && k.is_finite()) {
        return Err(ParamError::new("stiffness", format!("must be > 0 (N/m), got {k}")));
    }
    let d = number(t, "damping", Some(0.0))?;
    if !(d >= 0.0 && d.is_finite()) {
        return Err(ParamError::new("damping", format!("must be ≥ 0 (N·s/m), got {d}")));
    }
    Ok(Arc::new(Compliant { mu, k, d }))
}

fn parse_mohr_coulomb(t: &toml::Table) -> Result<Arc<dyn Law>, ParamError> {
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
    Ok(Arc::new(MohrCoulomb {
        mu,
        cohesion,
        tensile: tensile.min(apex),
        bond_gap,
    }))
}

/// The framework's own laws: `coulomb`, `frictionless`, `mohr_coulomb`, `compliant`.
pub(crate) fn builtin() -> [LawDef; 4] {
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
        LawDef {
            name: "compliant",
            parse: parse_compliant,
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
