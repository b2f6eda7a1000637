//! The ties of an overlap band: one bilateral constraint per grain,
//! v_p − N(ξ_p) V = ū_p (docs/CONTINUUM.md), its multiplier λ_p (an impulse,
//! N·s) acting +λ_p on the grain's centre and −λ_p on the continuum's material
//! point ξ_p (its D + 1 element nodes with the weights N_k(ξ_p)).
//!
//! A tie is solved as a contact with the bilateral law: its Delassus block
//! W_p = M̂_p⁻¹ (the grain's translational block) + Σ_kl N_k N_l G_kl (the continuum's,
//! through the block G of M̂⁻¹ among the tie nodes, [`crate::nodes::NodeSet`]) is
//! positive definite whatever the mesh and the grains, and the NLGS update is
//! λ_p ← λ_p − W_p⁻¹ (u_p − ū_p). The target closes the tie's gap
//! g_p = x_p − Σ N_k x_k within the step, ū = −(g + h(1 − θ) u⁻)/(hθ), so that
//! the grain stays on its material point (no drift).

use crate::nodes::NodeSet;
use nscdd::dim::Dim;
use nscdd::norms::Sums;

/// Ties of one step, one `Vec` per field: the grain (world body, or local copy in
/// a subdomain's part), the continuum body (or local entity), the element nodes
/// (indices in the body's [`NodeSet`]; `N + 1` used) and their weights, W_p and
/// W_p⁻¹, the target ū, the impulse λ, u_free (for the residual), the grain's
/// discrete weight w_p.
#[derive(Clone, Debug, Default)]
pub struct TieSet<const N: usize> {
    pub grain: Vec<u32>,
    pub body: Vec<u32>,
    pub k: Vec<[u32; 4]>,
    pub xi: Vec<[f64; 4]>,
    pub w: Vec<[[f64; N]; N]>,
    pub inv_w: Vec<[[f64; N]; N]>,
    pub target: Vec<[f64; N]>,
    pub r: Vec<[f64; N]>,
    pub u_free: Vec<[f64; N]>,
}

impl<const N: usize> TieSet<N> {
    pub fn len(&self) -> usize {
        self.grain.len()
    }
    pub fn is_empty(&self) -> bool {
        self.grain.is_empty()
    }
    /// Appends tie `a` of `src` with its grain and body renamed.
    pub fn push_from(&mut self, src: &Self, a: usize, grain: u32, body: u32) {
        self.grain.push(grain);
        self.body.push(body);
        self.k.push(src.k[a]);
        self.xi.push(src.xi[a]);
        self.w.push(src.w[a]);
        self.inv_w.push(src.inv_w[a]);
        self.target.push(src.target[a]);
        self.r.push(src.r[a]);
        self.u_free.push(src.u_free[a]);
    }
}

/// The continuum's velocity at a tie's material point: Σ_k N_k v_k.
#[inline(always)]
pub fn point_velocity<const N: usize>(set: &NodeSet<N>, k: &[u32; 4], xi: &[f64; 4]) -> [f64; N] {
    let mut u = [0.0; N];
    for q in 0..=N {
        let v = set.v[k[q] as usize];
        for c in 0..N {
            u[c] += xi[q] * v[c];
        }
    }
    u
}

/// The grain's translational velocity (the first N values of its twist).
#[inline(always)]
pub fn grain_velocity<D: Dim, const N: usize>(v: &D::Twist) -> [f64; N] {
    std::array::from_fn(|c| v.as_ref()[c])
}

/// u_p = v_p − N(ξ_p) V.
#[inline(always)]
pub fn tie_velocity<D: Dim, const N: usize>(v: &D::Twist, set: &NodeSet<N>, k: &[u32; 4], xi: &[f64; 4]) -> [f64; N] {
    let (a, b) = (grain_velocity::<D, N>(v), point_velocity(set, k, xi));
    std::array::from_fn(|c| a[c] - b[c])
}

/// Applies the impulse increment Δλ: +Δλ at the grain's centre, −Δλ at the
/// material point.
#[inline(always)]
pub fn apply<D: Dim, const N: usize>(set: &mut NodeSet<N>, v: &mut D::Twist, inv: &D::InvMass, k: &[u32; 4], xi: &[f64; 4], dr: [f64; N]) {
    let mut f = D::Twist::default();
    f.as_mut()[..N].copy_from_slice(&dr);
    D::apply_inv(v, inv, &f);
    for q in 0..=N {
        set.apply(k[q] as usize, dr.map(|x| -xi[q] * x));
    }
}

/// W_p: the grain's translational block of M̂⁻¹ (its copy's) plus the material
/// point's Σ_kl N_k N_l G_kl.
pub fn delassus<D: Dim, const N: usize>(set: &NodeSet<N>, inv: &D::InvMass, k: &[u32; 4], xi: &[f64; 4]) -> [[f64; N]; N] {
    let mut w = [[0.0; N]; N];
    for (c, row) in w.iter_mut().enumerate() {
        let (mut v, mut f) = (D::Twist::default(), D::Twist::default());
        f.as_mut()[c] = 1.0;
        D::apply_inv(&mut v, inv, &f);
        row.copy_from_slice(&v.as_ref()[..N]);
    }
    for p in 0..=N {
        for q in 0..=N {
            let b = set.block(k[p] as usize, k[q] as usize);
            let ww = xi[p] * xi[q];
            for c in 0..N {
                for d in 0..N {
                    w[c][d] += ww * b[c][d];
                }
            }
        }
    }
    w
}

/// The inverse of a small symmetric positive definite matrix (Gauss–Jordan; the
/// ties' W_p, N ≤ 3). None when singular.
pub fn inverse<const N: usize>(a: [[f64; N]; N]) -> Option<[[f64; N]; N]> {
    let mut m = a;
    let mut inv = [[0.0; N]; N];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for c in 0..N {
        let p = (c..N).max_by(|&x, &y| m[x][c].abs().total_cmp(&m[y][c].abs()))?;
        if !(m[p][c].abs() > 0.0) {
            return None;
        }
        m.swap(c, p);
        inv.swap(c, p);
        let d = m[c][c];
        for j in 0..N {
            m[c][j] /= d;
            inv[c][j] /= d;
        }
        for i in (0..N).filter(|&i| i != c) {
            let f = m[i][c];
            for j in 0..N {
                m[i][j] -= f * m[c][j];
                inv[i][j] -= f * inv[c][j];
            }
        }
    }
    Some(inv)
}

#[inline(always)]
pub fn mul<const N: usize>(a: &[[f64; N]; N], x: &[f64; N]) -> [f64; N] {
    std::array::from_fn(|i| (0..N).map(|j| a[i][j] * x[j]).sum())
}

/// One NLGS sweep over the ties (storage order): λ ← λ − W⁻¹ (u − ū), relaxed by ω;
/// a check pass adds to `sums` (LMGC90's sums, as a contact's).
pub fn sweep<D: Dim, const N: usize>(
    t: &mut TieSet<N>,
    sets: &mut [NodeSet<N>],
    vel: &mut [D::Twist],
    inv: &[D::InvMass],
    omega: f64,
    mut sums: Option<&mut Sums>,
) {
    for a in 0..t.len() {
        let (g, b) = (t.grain[a] as usize, t.body[a] as usize);
        let (k, xi) = (t.k[a], t.xi[a]);
        let u = tie_velocity::<D, N>(&vel[g], &sets[b], &k, &xi);
        let du: [f64; N] = std::array::from_fn(|c| u[c] - t.target[a][c]);
        let r = t.r[a];
        let step = mul(&t.inv_w[a], &du);
        let rn: [f64; N] = std::array::from_fn(|c| r[c] - omega * step[c]);
        let dr: [f64; N] = std::array::from_fn(|c| rn[c] - r[c]);
        if let Some(s) = sums.as_deref_mut() {
            let (wr_old, wr) = (mul(&t.w[a], &r), mul(&t.w[a], &rn));
            let dv: [f64; N] = std::array::from_fn(|c| wr[c] - wr_old[c]);
            s.add(&r, &rn, &dv, &wr_old, &wr);
        }
        if dr.iter().any(|&x| x != 0.0) {
            t.r[a] = rn;
            apply::<D, N>(&mut sets[b], &mut vel[g], &inv[g], &k, &xi, dr);
        }
    }
}

/// Warm start: the kept impulses applied to both sides.
pub fn warm_start<D: Dim, const N: usize>(t: &TieSet<N>, sets: &mut [NodeSet<N>], vel: &mut [D::Twist], inv: &[D::InvMass]) {
    for a in 0..t.len() {
        if t.r[a].iter().any(|&x| x != 0.0) {
            let (g, b) = (t.grain[a] as usize, t.body[a] as usize);
            apply::<D, N>(&mut sets[b], &mut vel[g], &inv[g], &t.k[a], &t.xi[a], t.r[a]);
        }
    }
}

/// W_p and W_p⁻¹ of every tie from the sets' G and the grains' copies' M̂⁻¹.
pub fn refresh_delassus<D: Dim, const N: usize>(t: &mut TieSet<N>, sets: &[NodeSet<N>], inv: &[D::InvMass]) {
    for a in 0..t.len() {
        let w = delassus::<D, N>(&sets[t.body[a] as usize], &inv[t.grain[a] as usize], &t.k[a], &t.xi[a]);
        t.w[a] = w;
        // W_p ≥ the grain's own M̂⁻¹ > 0 (a tied grain is movable)
        t.inv_w[a] = inverse(w).unwrap_or([[0.0; N]; N]);
    }
}

/// (‖F(λ)‖², ‖q‖²) of the ties for the natural-map residual: the bilateral law's
/// natural map is u − ū itself, q = u_free − ū.
pub fn residual_parts<D: Dim, const N: usize>(t: &TieSet<N>, sets: &[NodeSet<N>], vel: &[D::Twist]) -> (f64, f64) {
    let (mut f2, mut q2) = (0.0, 0.0);
    for a in 0..t.len() {
        let u = tie_velocity::<D, N>(&vel[t.grain[a] as usize], &sets[t.body[a] as usize], &t.k[a], &t.xi[a]);
        for c in 0..N {
            let (f, q) = (u[c] - t.target[a][c], t.u_free[a][c] - t.target[a][c]);
            f2 += f * f;
            q2 += q * q;
        }
    }
    (f2, q2)
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn inverse_of_spd() {
        let a = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];
        let b = inverse(a).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let x: f64 = (0..3).map(|k| a[i][k] * b[k][j]).sum();
                assert!((x - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
        assert!(inverse([[0.0, 0.0], [0.0, 1.0]]).is_none());
    }
}
