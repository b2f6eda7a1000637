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
pub fn norm2<V: AsRef<[f64]>>(v: &V, space: usize, rho2: f64) -> f64 {
    let v = v.as_ref();
    let mut s = 0.0;
    for &x in &v[..space] {
        s += x * x;
    }
    for &x in &v[space..] {
        s += rho2 * x * x;
    }
    s
}

/// V_{l+1} − V_l.
#[inline]
fn diff<V: Copy + Default + AsRef<[f64]> + AsMut<[f64]>>(a: &V, b: &V) -> V {
    let mut out = V::default();
    for ((o, x), y) in out.as_mut().iter_mut().zip(a.as_ref()).zip(b.as_ref()) {
        *o = x - y;
    }
    out
}

/// Σ_l |V_{l+1} − V_l|² / m over the links of one chain of m copies.
pub fn link_sum<V: Copy + Default + AsRef<[f64]> + AsMut<[f64]>>(v: &[V], space: usize, rho2: f64) -> f64 {
    let m = v.len() as f64;
    let mut s = 0.0;
    for l in 1..v.len() {
        let j = diff(&v[l], &v[l - 1]);
        s += norm2(&j, space, rho2) / m;
    }
    s
}

/// Reusable buffers of [`chain_increments`].
pub struct ChainScratch<V> {
    c: Vec<f64>,
    d: Vec<V>,
}

impl<V> Default for ChainScratch<V> {
    fn default() -> Self {
        ChainScratch {
            c: Vec::new(),
            d: Vec::new(),
        }
    }
}

/// ΔV_k = y_k − y_{k−1} with y = L⁻¹ [V] for the copies `v` (chain order), written
/// to `dv` (same length). One link in closed form, a Thomas solve beyond.
pub fn chain_increments<V: Copy + Default + AsRef<[f64]> + AsMut<[f64]>>(v: &[V], dv: &mut [V], s: &mut ChainScratch<V>) {
    let m = v.len();
    debug_assert_eq!(dv.len(), m);
    let jump = |l: usize| diff(&v[l + 1], &v[l]);
    match m {
        0 => {}
        1 => dv[0] = V::default(),
        2 => {
            let j = jump(0);
            let (mut y, mut ny) = (V::default(), V::default());
            for ((a, b), x) in y.as_mut().iter_mut().zip(ny.as_mut()).zip(j.as_ref()) {
                *a = 0.5 * x;
                *b = -*a;
            }
            dv[0] = y;
            dv[1] = ny;
        }
        _ => {
            // Thomas: L = tridiag(−1, 2, −1), n = m − 1 unknowns per degree of freedom
            let n = m - 1;
            s.c.clear();
            s.d.clear();
            for l in 0..n {
                let j = jump(l);
                let (cp, dp) = if l == 0 { (0.0, V::default()) } else { (s.c[l - 1], s.d[l - 1]) };
                let den = 2.0 + cp; // b − a c'_{l−1} with a = −1, b = 2
                s.c.push(-1.0 / den);
                let mut d = V::default();
                for ((o, x), p) in d.as_mut().iter_mut().zip(j.as_ref()).zip(dp.as_ref()) {
                    *o = (x + p) / den;
                }
                s.d.push(d);
            }
            // back substitution into s.d (y)
            for l in (0..n - 1).rev() {
                let (c, y1) = (s.c[l], s.d[l + 1]);
                for (y, x1) in s.d[l].as_mut().iter_mut().zip(y1.as_ref()) {
                    *y -= c * x1;
                }
            }
            for (k, out) in dv.iter_mut().enumerate() {
                let yk = if k < n { s.d[k] } else { V::default() };
                let ykm = if k > 0 { s.d[k - 1] } else { V::default() };
                *out = diff(&yk, &ykm);
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
            let mut dv = vec![[0.0; 3]; m];
            let mut s: ChainScratch<[f64; 3]> = ChainScratch::default();
            chain_increments(&v, &mut dv, &mut s);
            let mean: Vec<f64> = (0..3).map(|d| v.iter().map(|x| x[d]).sum::<f64>() / m as f64).collect();
            for k in 0..m {
                for d in 0..3 {
                    assert!((v[k][d] + dv[k][d] - mean[d]).abs() < 1e-12, "m {m} copy {k}");
                }
            }
        }
    }
}
