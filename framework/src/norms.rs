//! Convergence of the contact solver: LMGC90's norms and the natural-map residual.
//!
//! A *check pass* visits every contact and records, beside the newly solved pair
//! `(r, u)`, the pair `(r', u')` it held before being solved. With
//! `Δu = u − u'` and `r̄ = ½ (r + r')`, [`Sums`] accumulates (W is the contact's
//! diagonal block W_αα):
//!
//! ```text
//! SumDVDV   = Σ |Δu|²                SumWRWR = Σ ½ (|W r|² + |W r'|²)
//! SumWRR    = Σ ½ (r·W r + r'·W r')  SumDVDVRR = Σ |Δu|² |r̄|²
//! SumDVoR   = Σ r̄·Δu                 MaxDVDV, MaxDVDVRR (maxima), Nactif = #{r ≠ 0}
//! ```
//!
//! and [`Norms::from_sums`] forms, for a tolerance `tol`:
//!
//! ```text
//! QuadWR  = √(SumWRWR / Nactif)
//! QuadDV  = √(SumDVDV / Nactif) / (QuadWR tol)      MaxmDV  = √MaxDVDV / (QuadWR tol)
//! MeanWRR = SumWRR / Nactif
//! QuadDVR = √(SumDVDVRR / Nactif) / (MeanWRR tol)   MaxmDVR = √MaxDVDVRR / (MeanWRR tol)
//! MeanDVoR = SumDVoR / (SumWRR tol)
//! ```
//!
//! `Quad`: |MeanDVoR| < 1 ∧ QuadDV < 1 ∧ QuadDVR < 1; `Maxm`: the same with the
//! Maxm terms; `QM/16`: Quad ∧ MaxmDV < 16.666 ∧ MaxmDVR < 16.666.
//!
//! As in LMGC90 (`compute_convergence_norms_nlgs`), impulses are taken as vanishing
//! when `SumWRR ≤ 1e-18` or `SumWRWR ≤ 1e-18` ([`VANISHING`], SI units): the norms
//! are then 0 and the check passes. Without that guard, a step whose only non-zero
//! impulses are round-off (e.g. two balls touching at equal velocities after an
//! impact, u_n ≈ ±1e-16) never converges: relative changes of round-off stay O(1).
//!
//! Sums are plain additions, so the sums of several subdomains reduce to the sums of
//! the whole problem ([`Sums::merge`]) and the test is the same as for one domain.
//! The solver-independent measure is [`natural_map_sq`], summed by `solver::nlgs::residual`.

use serde::{Deserialize, Serialize};

/// The convergence criterion, by LMGC90's names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Criterion {
    #[serde(rename = "Quad")]
    Quad,
    #[serde(rename = "Maxm")]
    Maxm,
    #[serde(rename = "QM/16")]
    QuadMax16,
}

impl Criterion {
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "Quad" | "quad" => Some(Self::Quad),
            "Maxm" | "maxm" => Some(Self::Maxm),
            "QM/16" | "qm/16" => Some(Self::QuadMax16),
            _ => None,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Self::Quad => "Quad",
            Self::Maxm => "Maxm",
            Self::QuadMax16 => "QM/16",
        }
    }
}

/// Accumulated check-pass sums (reducible over subdomains).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Sums {
    pub sum_dvdv: f64,
    pub sum_wrwr: f64,
    pub sum_wrr: f64,
    pub sum_dvdvrr: f64,
    pub sum_dvor: f64,
    pub max_dvdv: f64,
    pub max_dvdvrr: f64,
    pub nactif: u64,
}

impl Sums {
    /// Whether every sum is finite: an overflow (impulses or velocities near 10³⁰⁸, a
    /// diverging scene) makes the norms meaningless, and the solve stops there
    /// unconverged rather than sweeping on infinities.
    pub fn is_finite(&self) -> bool {
        [
            self.sum_dvdv,
            self.sum_wrwr,
            self.sum_wrr,
            self.sum_dvdvrr,
            self.sum_dvor,
            self.max_dvdv,
            self.max_dvdvrr,
        ]
        .iter()
        .all(|x| x.is_finite())
    }
    /// Adds one contact. `r_old`, `r`: impulses before and after solving; `du = u − u'`;
    /// `wr_old = W_αα r'`, `wr = W_αα r`.
    #[inline]
    pub fn add(&mut self, r_old: &[f64], r: &[f64], du: &[f64], wr_old: &[f64], wr: &[f64]) {
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let dvdv = dot(du, du);
        let mut rbar2 = 0.0;
        let mut dvor = 0.0;
        for k in 0..r.len() {
            let rb = 0.5 * (r[k] + r_old[k]);
            rbar2 += rb * rb;
            dvor += rb * du[k];
        }
        self.sum_dvdv += dvdv;
        self.sum_wrwr += 0.5 * (dot(wr, wr) + dot(wr_old, wr_old));
        self.sum_wrr += 0.5 * (dot(r, wr) + dot(r_old, wr_old));
        self.sum_dvdvrr += dvdv * rbar2;
        self.sum_dvor += dvor;
        self.max_dvdv = self.max_dvdv.max(dvdv);
        self.max_dvdvrr = self.max_dvdvrr.max(dvdv * rbar2);
        if r.iter().any(|&x| x != 0.0) {
            self.nactif += 1;
        }
    }

    /// Reduction of the sums of two parts of one problem.
    pub fn merge(&mut self, o: &Sums) {
        self.sum_dvdv += o.sum_dvdv;
        self.sum_wrwr += o.sum_wrwr;
        self.sum_wrr += o.sum_wrr;
        self.sum_dvdvrr += o.sum_dvdvrr;
        self.sum_dvor += o.sum_dvor;
        self.max_dvdv = self.max_dvdv.max(o.max_dvdv);
        self.max_dvdvrr = self.max_dvdvrr.max(o.max_dvdvrr);
        self.nactif += o.nactif;
    }
}

/// LMGC90's normalised convergence measures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Norms {
    pub quad_dv: f64,
    pub quad_dvr: f64,
    pub maxm_dv: f64,
    pub maxm_dvr: f64,
    pub mean_dvor: f64,
    pub nactif: u64,
}

/// `SumWRR` or `SumWRWR` at or below this value: the impulses vanish (LMGC90).
pub const VANISHING: f64 = 1e-18;

/// Bound of the maxima over the quadratic norms in `QM/16`.
pub const QM_FACTOR: f64 = 16.666;

impl Norms {
    pub fn from_sums(s: &Sums, tol: f64) -> Self {
        if s.nactif == 0 {
            return Norms::default();
        }
        // LMGC90's guard: round-off impulses (NaN sums fail the test and stay NaN)
        if s.sum_wrr <= VANISHING || s.sum_wrwr <= VANISHING {
            return Norms {
                nactif: s.nactif,
                ..Norms::default()
            };
        }
        let n = s.nactif as f64;
        let quad_wr = (s.sum_wrwr / n).sqrt();
        let mean_wrr = s.sum_wrr / n;
        let safe = |num: f64, den: f64| if num == 0.0 { 0.0 } else { num / den };
        Norms {
            quad_dv: safe((s.sum_dvdv / n).sqrt(), quad_wr * tol),
            maxm_dv: safe(s.max_dvdv.sqrt(), quad_wr * tol),
            quad_dvr: safe((s.sum_dvdvrr / n).sqrt(), mean_wrr * tol),
            maxm_dvr: safe(s.max_dvdvrr.sqrt(), mean_wrr * tol),
            mean_dvor: safe(s.sum_dvor, s.sum_wrr * tol),
            nactif: s.nactif,
        }
    }

    /// Whether the criterion holds. NaN norms never converge.
    pub fn converged(&self, c: Criterion) -> bool {
        let quad = self.mean_dvor.abs() < 1.0 && self.quad_dv < 1.0 && self.quad_dvr < 1.0;
        match c {
            Criterion::Quad => quad,
            Criterion::Maxm => self.mean_dvor.abs() < 1.0 && self.maxm_dv < 1.0 && self.maxm_dvr < 1.0,
            Criterion::QuadMax16 => quad && self.maxm_dv < QM_FACTOR && self.maxm_dvr < QM_FACTOR,
        }
    }
}

/// Natural-map residual of one contact, squared: `|r − P_K(r − (u + Φ(u)))|²` with
/// De Saxcé's `Φ(u) = (μ |u_t|, 0, ..)` and K the Coulomb cone `|r_t| ≤ μ r_n`.
/// Works in 2D (`r.len() == 2`) and 3D (`r.len() == 3`); the normal comes first.
pub fn natural_map_sq(r: &[f64], u: &[f64], mu: f64) -> f64 {
    let d = r.len();
    let ut_norm = u[1..].iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut z = [0.0; 3];
    z[0] = r[0] - (u[0] + mu * ut_norm);
    for k in 1..d {
        z[k] = r[k] - u[k];
    }
    let p = project_cone(&z[..d], mu);
    (0..d).map(|k| (r[k] - p[k]).powi(2)).sum()
}

/// Projection on the Coulomb cone `{ |z_t| ≤ μ z_n }`.
pub fn project_cone(z: &[f64], mu: f64) -> [f64; 3] {
    let zn = z[0];
    let zt = z[1..].iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut out = [0.0; 3];
    // zn ≥ 0 matters for μ = 0: then the cone is the half-line z_t = 0, z_n ≥ 0
    if zn >= 0.0 && zt <= mu * zn {
        out[..z.len()].copy_from_slice(z);
    } else if mu * zt <= -zn {
        // polar cone: projection is the apex
    } else {
        let a = (zn + mu * zt) / (1.0 + mu * mu);
        out[0] = a;
        if zt > 0.0 {
            for k in 1..z.len() {
                out[k] = mu * a * z[k] / zt;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn projection() {
        assert_eq!(project_cone(&[1.0, 0.2], 0.5), [1.0, 0.2, 0.0]);
        assert_eq!(project_cone(&[-1.0, 0.2], 0.5), [0.0, 0.0, 0.0]);
        let p = project_cone(&[0.0, 1.0], 1.0);
        assert!((p[0] - 0.5).abs() < 1e-15 && (p[1] - 0.5).abs() < 1e-15);
        assert_eq!(natural_map_sq(&[1.0, 0.0], &[0.0, 0.0], 0.3), 0.0);
        // frictionless: a separating contact without impulse satisfies the law
        assert_eq!(project_cone(&[-4.0, 0.0], 0.0), [0.0, 0.0, 0.0]);
        assert_eq!(natural_map_sq(&[0.0, 0.0], &[4.0, 0.0], 0.0), 0.0);
    }
    #[test]
    fn round_off_impulses_converge() {
        // one contact whose impulse is round-off and changes by 100 % per sweep
        let mut s = Sums::default();
        s.add(&[1e-15, 0.0], &[2e-15, 0.0], &[2.5e-16, 0.0], &[2.5e-16, 0.0], &[5e-16, 0.0]);
        assert!(Norms::from_sums(&s, 1e-4).converged(Criterion::QuadMax16));
        let mut nan = s;
        // a NaN impulse makes every sum NaN: never converged
        (nan.sum_dvdv, nan.sum_wrr, nan.sum_wrwr) = (f64::NAN, f64::NAN, f64::NAN);
        assert!(!Norms::from_sums(&nan, 1e-4).converged(Criterion::QuadMax16));
    }
    #[test]
    fn empty_sums_converge() {
        let n = Norms::from_sums(&Sums::default(), 1e-4);
        assert!(n.converged(Criterion::QuadMax16));
    }
}
