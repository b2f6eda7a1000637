//! Storage of the contact set of one time step, for any dimension: one `Vec` per
//! field, a field being what one stage reads together (the bodies of a contact, its
//! frame, its Delassus block, its law targets, its impulse), so that an NLGS sweep
//! streams five arrays. Measured: grouping the hot data this way instead of one
//! `Vec` per scalar made the 2D sweep 1.75× faster (docs/PERFORMANCE.md).

use crate::dim::joint::Joint;
use crate::dim::{Dim, Vector};
use serde::{Deserialize, Serialize};

/// Identity of a contact between steps: the two bodies and a feature index (for
/// shapes that touch at several points). Used to carry impulses over (warm start).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct ContactKey {
    pub i: u32,
    pub j: u32,
    pub feature: u32,
}

/// What the law asks of a contact: the target normal velocity ū (u_n ≥ ū ⊥ r_n ≥ 0)
/// and the friction coefficient μ.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[repr(C)]
pub struct Target {
    pub u_target: f64,
    pub mu: f64,
}

/// Contacts, indexed by dense ids. The first five fields are the NLGS sweep's.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(bound = "")]
pub struct Contacts<D: Dim> {
    /// (candidate i, antagonist j).
    pub bodies: Vec<[u32; 2]>,
    pub frame: Vec<D::Frame>,
    pub block: Vec<D::Block>,
    pub target: Vec<Target>,
    /// Impulse r (normal first).
    pub r: Vec<D::Local>,
    /// Local free velocity u_free = Hᵀ V_free.
    pub u_free: Vec<D::Local>,
    /// Gap at the start of the step.
    pub gap: Vec<f64>,
    /// Contact point.
    pub point: Vec<D::Point>,
    pub key: Vec<ContactKey>,
    /// Strengths of bonded joints (zero for other contacts).
    pub joint: Vec<Joint>,
    /// Normal compliance c ≥ 0 of each contact (law `compliant`: the normal law is
    /// u_n + c r_n ≥ ū ⊥ r_n ≥ 0), added to W_nn in its `block`; one per contact
    /// when `compliant`, else empty (rigid contacts, the common case, carry none).
    #[serde(default)]
    pub compliance: Vec<f64>,
    /// Whether some contact has c > 0 (set by whoever fills `compliance`: the
    /// contact build, [`Contacts::push_from`]).
    #[serde(default)]
    pub compliant: bool,
}

macro_rules! each_field {
    ($s:ident, $f:ident $(, $arg:expr)*) => {
        $s.bodies.$f($($arg)*);
        $s.frame.$f($($arg)*);
        $s.block.$f($($arg)*);
        $s.target.$f($($arg)*);
        $s.r.$f($($arg)*);
        $s.u_free.$f($($arg)*);
        $s.gap.$f($($arg)*);
        $s.point.$f($($arg)*);
        $s.key.$f($($arg)*);
        $s.joint.$f($($arg)*);
    };
}

impl<D: Dim> Contacts<D> {
    pub fn len(&self) -> usize {
        self.bodies.len()
    }
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
    }
    /// Contact `a`'s point as three coordinates (z = 0 in 2D).
    pub fn point3(&self, a: usize) -> [f64; 3] {
        let mut p = [0.0; 3];
        p[..D::N].copy_from_slice(self.point[a].as_ref());
        p
    }
    pub fn clear(&mut self) {
        each_field!(self, clear);
        self.compliance.clear();
        self.compliant = false;
    }
    /// Room for `n` more contacts in every field.
    pub fn reserve(&mut self, n: usize) {
        each_field!(self, reserve, n);
    }

    /// Appends contact `a` of `other` with its bodies renamed (i, j).
    pub fn push_from(&mut self, other: &Contacts<D>, a: usize, i: u32, j: u32) {
        self.bodies.push([i, j]);
        self.frame.push(other.frame[a]);
        self.block.push(other.block[a]);
        self.target.push(other.target[a]);
        self.r.push(other.r[a]);
        self.u_free.push(other.u_free[a]);
        self.gap.push(other.gap[a]);
        self.point.push(other.point[a]);
        self.key.push(other.key[a]);
        self.joint.push(other.joint[a]);
        if other.compliant {
            // contacts come from one source: all compliant or none
            self.compliance.push(other.compliance[a]);
            self.compliant = true;
        }
    }

    /// Keeps the contacts `a` for which `keep(a)` holds, in their order.
    pub fn retain(&mut self, mut keep: impl FnMut(usize) -> bool) {
        let mut out = Contacts::default();
        for a in (0..self.len()).filter(|&a| keep(a)) {
            let [i, j] = self.bodies[a];
            out.push_from(self, a, i, j);
        }
        *self = out;
    }

    /// Whether some contact is a bonded joint (the sweep then takes the joint path).
    pub fn any_bonded(&self) -> bool {
        self.joint.iter().any(|j| j.bonded())
    }

    /// Local velocity u_α = H_iᵀ V_i − H_jᵀ V_j from body velocities.
    #[inline(always)]
    pub fn local_velocity(&self, a: usize, vel: &[D::Twist]) -> D::Local {
        let [i, j] = self.bodies[a];
        D::local_velocity(&self.frame[a], &vel[i as usize], &vel[j as usize])
    }

    /// Applies the impulse increment `dr` of contact α to its bodies: V += M̂⁻¹ H Δr.
    #[inline(always)]
    pub fn apply(&self, a: usize, dr: &D::Local, vel: &mut [D::Twist], inv: &[D::InvMass]) {
        let [i, j] = self.bodies[a];
        D::apply(&self.frame[a], dr, i as usize, j as usize, vel, inv);
    }

    /// Sets contact α's impulse to `r` (its first D::Local::LEN values), its bodies
    /// following: V += M̂⁻¹ H (r − r_α).
    #[inline]
    pub fn set_r(&mut self, a: usize, r: &[f64], vel: &mut [D::Twist], inv: &[D::InvMass]) {
        let r = <D::Local as Vector>::from_fn(|k| r[k]);
        let dr = r.sub(&self.r[a]);
        if !dr.is_zero() {
            self.apply(a, &dr, vel, inv);
            self.r[a] = r;
        }
    }

    /// V += M̂⁻¹ H r for every contact with r ≠ 0, in storage order (the warm start).
    pub fn apply_all(&self, vel: &mut [D::Twist], inv: &[D::InvMass]) {
        for a in 0..self.len() {
            if !self.r[a].is_zero() {
                self.apply(a, &self.r[a], vel, inv);
            }
        }
    }

    /// W_αα (and the local solver's precomputed data) from the bodies' M̂⁻¹ (an
    /// NSCDD subdomain's copies) of the contacts whose pair of bodies `which`
    /// selects; the others keep their block.
    pub fn refresh_delassus_of(&mut self, inv: &[D::InvMass], which: impl Fn([u32; 2]) -> bool) {
        for a in 0..self.len() {
            let [i, j] = self.bodies[a];
            if !which([i, j]) {
                continue;
            }
            let w = D::delassus(&self.frame[a], &inv[i as usize], &inv[j as usize]);
            let w = if self.compliant {
                D::with_compliance(w, self.compliance[a])
            } else {
                w
            };
            self.block[a] = D::block(w, self.target[a].mu);
        }
    }
}

impl<D: Dim> Contacts<D> {
    /// World impulse B r of contact α (on its candidate body i).
    pub fn world_impulse(&self, a: usize) -> D::Point {
        D::to_world(&self.frame[a], &self.r[a])
    }
}
