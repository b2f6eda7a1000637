//! The gluing of one interface body: the chain solve and the gluing residual.
//!
//! A body i with multiplicity m has copies k = 0..m−1 (in subdomain order), each
//! with M̂_E = M̂/m, chained by m − 1 links: link l joins copies l and l + 1 and
//! carries a multiplier λ_l acting +λ_l on copy l and −λ_l on copy l + 1. The net
//! interface impulse on copy k is F_Γ,k = λ_k − λ_{k−1} (λ_{−1} = λ_{m−1} = 0), so
//! Σ_k F_Γ,k = 0 and the copies' impulses add up to the body's: Σ_E M̂_E (V_E −
//! V_free) = Σ_E H_E r_E. With the jumps [V]_l = V_{l+1} − V_l and the contact
//! impulses fixed, the multiplier update that cancels every jump is
//!
//! ```text
//! L Δλ = M̂_E [V],   L = tridiag(−1, 2, −1) of size m − 1      (DESIGN.md §3)
//! ```
//!
//! With y = L⁻¹ [V] (a velocity), Δλ = M̂_E y, ΔF_Γ,k = M̂_E (y_k − y_{k−1}) and the
//! copies move by ΔV_k = M̂_E⁻¹ ΔF_Γ,k = y_k − y_{k−1}. One link: y = ½ [V], both
//! copies go to their mean. In general the copies all go to their mean (the ΔV_k
//! sum to zero and cancel the jumps); the chain form is kept because it is the one
//! that carries over to copies of unequal M̂_E (subdomains formed by model).
//!
//! The gluing residual (DESIGN.md §3, LMGC90's `egluing`) over all interface bodies:
//!
//! ```text
//! egluing = √( Σ_links |[V]_link|² / m_link ) / n_links
//! ```
//!
//! with m_link the multiplicity m_i of the body the link belongs to (each body's m_i
//! − 1 links together weigh (m_i − 1)/m_i: a corner body does not count three times
//! a face body) and |·| the body's kinetic norm per unit mass,
//! |V|² = |v|² + (I/m) |ω|² (in 3D I/m the mean of the principal moments over m), so
//! that translation and rotation add in m/s.
//! It is made dimensionless by the same velocity scale as LMGC90's QuadDV, QuadWR =
//! √(SumWRWR / Nactif) (the mean velocity that contact impulses produce; it stays
//! finite in a pile at rest, where the copies' own velocities vanish):
//! egluing_rel = egluing / QuadWR, tested against the solver's `tol`. When the
//! impulses vanish (QuadWR = 0), the RMS velocity of the interface copies is the
//! scale instead (and egluing_rel = 0 when the jumps are exactly 0).

/// One subdomain's share of the gluing residual.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct GluePartial {
    /// Σ |[V]_link|² / m_link over the links whose first copy the subdomain holds.
    pub jump2: f64,
    pub links: u64,
    /// Σ |V_copy|² over the subdomain's interface copies.
    pub v2: f64,
    pub copies: u64,
}

impl GluePartial {
    pub fn merge(&mut self, o: &GluePartial) {
        self.jump2 += o.jump2;
        self.links += o.links;
        self.v2 += o.v2;
        self.copies += o.copies;
    }
    /// egluing = √(Σ |[V]|²/m) / n_links (0 without links).
    pub fn egluing(&self) -> f64 {
        if self.links == 0 {
            0.0
        } else {
            self.jump2.sqrt() / self.links as f64
        }
    }
    /// egluing / QuadWR, or relative to the RMS copy velocity when `quad_wr` is 0.
    pub fn relative(&self, quad_wr: f64) -> f64 {
        let e = self.egluing();
        if e == 0.0 {
            return 0.0;
        }
        if quad_wr > 0.0 {
            return e / quad_wr;
        }
        let v = if self.copies == 0 {
            0.0
        } else {
            (self.v2 / self.copies as f64).sqrt()
        };
        if v > 0.0 {
            e / v
        } else {
            f64::INFINITY
        }
    }
}

/// |V|² = |v|² + ρ² |ω|² with ρ² = I/m: the first `space` components of V are
/// translations, the others rotations.
#[inline]
pub fn norm2(v: &[f64], space: usize, rho2: f64) -> f64 {
    let mut s = 0.0;
    for &x in &v[..space] {
        s += x * x;
    }
    for &x in &v[space..] {
        s += rho2 * x * x;
    }
    s
}

/// Σ_l |V_{l+1} − V_l|² / m over the links of one chain of m copies of `d`
/// degrees of freedom each (`v`: the copies one after the other).
#[inline(always)]
pub fn link_sum(v: &[f64], d: usize, space: usize, rho2: f64) -> f64 {
    let m = v.len() / d;
    let mut s = 0.0;
    for l in 1..m {
        let (a, b) = (&v[l * d..(l + 1) * d], &v[(l - 1) * d..l * d]);
        // |a − b|² as norm2 sums it
        let mut n2 = 0.0;
        for i in 0..space {
            let x = a[i] - b[i];
            n2 += x * x;
        }
        for i in space..d {
            let x = a[i] - b[i];
            n2 += rho2 * x * x;
        }
        s += n2 / m as f64;
    }
    s
}

/// Reusable buffers of [`chain_increments`].
#[derive(Default)]
pub struct ChainScratch {
    c: Vec<f64>,
    y: Vec<f64>,
}

/// ΔV_k = y_k − y_{k−1} with y = L⁻¹ [V] for the m copies of `d` degrees of freedom
/// in `v` (chain order, one after the other), written to `dv` (same length). One
/// link in closed form, a Thomas solve beyond.
#[inline(always)]
pub fn chain_increments(v: &[f64], d: usize, dv: &mut [f64], s: &mut ChainScratch) {
    let m = v.len() / d;
    debug_assert_eq!(dv.len(), v.len());
    let jump = |l: usize, i: usize| v[(l + 1) * d + i] - v[l * d + i];
    match m {
        0 => {}
        1 => dv.iter_mut().for_each(|x| *x = 0.0),
        2 => {
            for i in 0..d {
                let y = 0.5 * jump(0, i);
                dv[i] = y;
                dv[d + i] = -y;
            }
        }
        _ => {
            // Thomas: L = tridiag(−1, 2, −1), n = m − 1 unknowns per degree of freedom
            let n = m - 1;
            s.c.clear();
            s.y.clear();
            for l in 0..n {
                let cp = if l == 0 { 0.0 } else { s.c[l - 1] };
                let den = 2.0 + cp; // b − a c'_{l−1} with a = −1, b = 2
                s.c.push(-1.0 / den);
                for i in 0..d {
                    let dp = if l == 0 { 0.0 } else { s.y[(l - 1) * d + i] };
                    s.y.push((jump(l, i) + dp) / den);
                }
            }
            // back substitution into s.y
            for l in (0..n - 1).rev() {
                let c = s.c[l];
                for i in 0..d {
                    let y1 = s.y[(l + 1) * d + i];
                    s.y[l * d + i] -= c * y1;
                }
            }
            for k in 0..m {
                for i in 0..d {
                    let yk = if k < n { s.y[k * d + i] } else { 0.0 };
                    let ykm = if k > 0 { s.y[(k - 1) * d + i] } else { 0.0 };
                    dv[k * d + i] = yk - ykm;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn chains_go_to_the_mean() {
        for m in 1..7 {
            let v: Vec<[f64; 3]> = (0..m).map(|k| [k as f64 * 1.5 - 2.0, (k * k) as f64, 0.3 * k as f64]).collect();
            let mut flat = vec![0.0; 3 * m];
            let mut s = ChainScratch::default();
            chain_increments(&v.concat(), 3, &mut flat, &mut s);
            let dv: Vec<&[f64]> = flat.chunks_exact(3).collect();
            let mean: Vec<f64> = (0..3).map(|d| v.iter().map(|x| x[d]).sum::<f64>() / m as f64).collect();
            for k in 0..m {
                for d in 0..3 {
                    assert!((v[k][d] + dv[k][d] - mean[d]).abs() < 1e-12, "m {m} copy {k}");
                }
            }
        }
    }
}
