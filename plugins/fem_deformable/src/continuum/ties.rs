//! The ties of an overlap band (docs/CONTINUUM.md): bilateral constraints on
//! velocities, each of the form
//!
//! ```text
//! u_a = Σ_i c_ai v_i − Σ_l b_al V_l = ū_a        (N components)
//! ```
//!
//! over grains i (their translational velocities v_i) and the continuum's tie
//! nodes l (V_l). Its multiplier λ_a (an impulse, N·s) acts +c_ai λ_a on grain i and
//! −b_al λ_a on node l (the constraint's transpose). Two couplings fill it:
//!
//! - **per grain** (`coupling = "grain"`): one tie per band grain p, c = 1 on p,
//!   b_l = N_l(ξ_p) on the D + 1 nodes of its cell: v_p = N(ξ_p) V;
//! - **per node** (`coupling = "node"`, the default): each band grain is given to
//!   the node k of its cell with the largest N_k(ξ_p); one tie per node holding
//!   grains, c_kp = m̃_p / Σ_q m̃_q over its grains (m̃ their band masses),
//!   b_kl = Σ_p c_kp N_l(ξ_p): the mass-weighted mean velocity of node k's grains
//!   equals the continuum's mean at them. The grains' sets are disjoint, so the
//!   ties are independent; the grains of a set may move relative to one another.
//!
//! A tie is solved as a contact with the bilateral law: its Delassus block
//! W_a = Σ_i c_ai² M̂_i⁻¹ (translational blocks) + Σ_ll' b_al b_al' G_ll' (the
//! block G of M̂⁻¹ among the tie nodes, [`crate::nodes::NodeSet`]) is positive
//! definite, and the NLGS update is λ_a ← λ_a − W_a⁻¹ (u_a − ū_a). The target
//! closes the tie's gap g_a = Σ c_ai x_i − Σ b_al x_l within the step,
//! ū = −(g + h(1 − θ) u⁻)/(hθ), so that the grains stay (on average, per node) on
//! their material points.

use crate::nodes::NodeSet;
use nscdd::dim::Dim;
use nscdd::norms::Sums;

/// Ties of one step (module docs), one `Vec` per field: the continuum body (or
/// local entity) of each, its grains `grain[g_start[a]..g_start[a + 1]]` (world
/// bodies, or local copies in a subdomain's part) with their c, its nodes
/// `node[n_start[a]..n_start[a + 1]]` (indices in the body's [`NodeSet`]) with their
/// b, W_a and W_a⁻¹, the target ū, the impulse λ, u_free (for the residual).
#[derive(Clone, Debug)]
pub struct TieSet<const N: usize> {
    pub body: Vec<u32>,
    pub g_start: Vec<u32>,
    pub grain: Vec<u32>,
    pub c: Vec<f64>,
    pub n_start: Vec<u32>,
    pub node: Vec<u32>,
    pub b: Vec<f64>,
    pub w: Vec<[[f64; N]; N]>,
    pub inv_w: Vec<[[f64; N]; N]>,
    pub target: Vec<[f64; N]>,
    pub r: Vec<[f64; N]>,
    pub u_free: Vec<[f64; N]>,
    /// Each tie's N columns −Σ_l b_al G_{·l} over its body's tie nodes (node-major,
    /// `col[col_start[a]..col_start[a + 1]]`), made with W_a when they fit
    /// ([`COLUMNS_MAX`]): a tie's impulse then moves the nodes through one column
    /// per component instead of one per node and component. Empty: not made.
    pub col: Vec<f64>,
    pub col_start: Vec<usize>,
}

/// The most values the ties' columns may take (8 · 10⁶: 64 MB).
pub const COLUMNS_MAX: usize = 8_000_000;

impl<const N: usize> Default for TieSet<N> {
    fn default() -> Self {
        TieSet {
            body: vec![],
            g_start: vec![0],
            grain: vec![],
            c: vec![],
            n_start: vec![0],
            node: vec![],
            b: vec![],
            w: vec![],
            inv_w: vec![],
            target: vec![],
            r: vec![],
            u_free: vec![],
            col: vec![],
            col_start: vec![],
        }
    }
}

impl<const N: usize> TieSet<N> {
    pub fn len(&self) -> usize {
        self.body.len()
    }
    pub fn is_empty(&self) -> bool {
        self.body.is_empty()
    }
    pub fn grains(&self, a: usize) -> std::ops::Range<usize> {
        self.g_start[a] as usize..self.g_start[a + 1] as usize
    }
    pub fn nodes(&self, a: usize) -> std::ops::Range<usize> {
        self.n_start[a] as usize..self.n_start[a + 1] as usize
    }
    /// Appends a tie of `body` over `grains` (id, c) and `nodes` (set index, b), at
    /// rest.
    pub fn push(&mut self, body: u32, grains: impl IntoIterator<Item = (u32, f64)>, nodes: impl IntoIterator<Item = (u32, f64)>) {
        self.col_start.clear();
        self.body.push(body);
        for (g, c) in grains {
            self.grain.push(g);
            self.c.push(c);
        }
        self.g_start.push(self.grain.len() as u32);
        for (l, b) in nodes {
            self.node.push(l);
            self.b.push(b);
        }
        self.n_start.push(self.node.len() as u32);
        self.w.push([[0.0; N]; N]);
        self.inv_w.push([[0.0; N]; N]);
        self.target.push([0.0; N]);
        self.r.push([0.0; N]);
        self.u_free.push([0.0; N]);
    }
    /// Appends tie `a` of `src` with its grains renamed by `grain` and its body
    /// `body`.
    pub fn push_from(&mut self, src: &Self, a: usize, grain: &mut dyn FnMut(u32) -> u32, body: u32) {
        let gs = src.grains(a).map(|i| (grain(src.grain[i]), src.c[i]));
        let ns = src.nodes(a).map(|j| (src.node[j], src.b[j]));
        self.push(body, gs.collect::<Vec<_>>(), ns);
        let k = self.len() - 1;
        self.w[k] = src.w[a];
        self.inv_w[k] = src.inv_w[a];
        self.target[k] = src.target[a];
        self.r[k] = src.r[a];
        self.u_free[k] = src.u_free[a];
    }
}

/// The grain's translational velocity (the first N values of its twist).
#[inline(always)]
pub fn grain_velocity<D: Dim, const N: usize>(v: &D::Twist) -> [f64; N] {
    std::array::from_fn(|c| v.as_ref()[c])
}

/// u_a = Σ c_ai v_i − Σ b_al V_l from the current velocities; grain i's at
/// `vel[at(i's id)]`.
#[inline(always)]
pub fn tie_velocity<D: Dim, const N: usize>(
    t: &TieSet<N>,
    a: usize,
    (vel, at): (&[D::Twist], impl Fn(u32) -> usize),
    set: &NodeSet<N>,
) -> [f64; N] {
    let mut u = [0.0; N];
    for i in t.grains(a) {
        let v = vel[at(t.grain[i])].as_ref();
        for c in 0..N {
            u[c] += t.c[i] * v[c];
        }
    }
    for j in t.nodes(a) {
        let v = set.v[t.node[j] as usize];
        for c in 0..N {
            u[c] -= t.b[j] * v[c];
        }
    }
    u
}

/// Applies the impulse increment Δλ of tie `a` to its grains and nodes.
#[inline(always)]
pub fn apply<D: Dim, const N: usize>(
    t: &TieSet<N>,
    a: usize,
    vel: &mut [D::Twist],
    inv: &[D::InvMass],
    set: &mut NodeSet<N>,
    dr: [f64; N],
) {
    for i in t.grains(a) {
        let g = t.grain[i] as usize;
        let mut f = D::Twist::default();
        for c in 0..N {
            f.as_mut()[c] = t.c[i] * dr[c];
        }
        D::apply_inv(&mut vel[g], &inv[g], &f);
    }
    if t.col_start.len() == t.len() + 1 {
        let col = &t.col[t.col_start[a]..t.col_start[a + 1]];
        let nd = col.len() / N;
        for (d, &x) in dr.iter().enumerate() {
            if x != 0.0 {
                let cd = &col[d * nd..(d + 1) * nd];
                for (v, g) in set.v.iter_mut().zip(cd.chunks_exact(N)) {
                    for c in 0..N {
                        v[c] += g[c] * x;
                    }
                }
            }
        }
        return;
    }
    for j in t.nodes(a) {
        set.apply(t.node[j] as usize, dr.map(|x| -t.b[j] * x));
    }
}

/// W_a (module docs) from the grains' copies' M̂⁻¹ and the set's G.
pub fn delassus<D: Dim, const N: usize>(t: &TieSet<N>, a: usize, inv: &[D::InvMass], set: &NodeSet<N>) -> [[f64; N]; N] {
    let mut w = [[0.0; N]; N];
    for i in t.grains(a) {
        let c2 = t.c[i] * t.c[i];
        for (c, row) in w.iter_mut().enumerate() {
            let (mut v, mut f) = (D::Twist::default(), D::Twist::default());
            f.as_mut()[c] = 1.0;
            D::apply_inv(&mut v, &inv[t.grain[i] as usize], &f);
            for (x, y) in row.iter_mut().zip(v.as_ref()) {
                *x += c2 * y;
            }
        }
    }
    for p in t.nodes(a) {
        for q in t.nodes(a) {
            let blk = set.block(t.node[p] as usize, t.node[q] as usize);
            let bb = t.b[p] * t.b[q];
            for c in 0..N {
                for d in 0..N {
                    w[c][d] += bb * blk[c][d];
                }
            }
        }
    }
    w
}

/// The inverse of a small symmetric positive definite matrix (Gauss–Jordan with
/// partial pivoting; the ties' W_a, N ≤ 3). None when singular.
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

/// One NLGS sweep over the ties (storage order): λ ← λ − ω W⁻¹ (u − ū); a check
/// pass adds to `sums` (LMGC90's sums, as a contact's).
pub fn sweep<D: Dim, const N: usize>(
    t: &mut TieSet<N>,
    sets: &mut [NodeSet<N>],
    vel: &mut [D::Twist],
    inv: &[D::InvMass],
    omega: f64,
    mut sums: Option<&mut Sums>,
) {
    for a in 0..t.len() {
        let set = &mut sets[t.body[a] as usize];
        let u = tie_velocity::<D, N>(t, a, (vel, |g| g as usize), set);
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
            apply::<D, N>(t, a, vel, inv, set, dr);
        }
    }
}

/// Warm start: the kept impulses applied to grains and nodes.
pub fn warm_start<D: Dim, const N: usize>(t: &TieSet<N>, sets: &mut [NodeSet<N>], vel: &mut [D::Twist], inv: &[D::InvMass]) {
    for a in 0..t.len() {
        if t.r[a].iter().any(|&x| x != 0.0) {
            apply::<D, N>(t, a, vel, inv, &mut sets[t.body[a] as usize], t.r[a]);
        }
    }
}

/// W_a and W_a⁻¹ of every tie.
pub fn refresh_delassus<D: Dim, const N: usize>(t: &mut TieSet<N>, sets: &[NodeSet<N>], inv: &[D::InvMass]) {
    for a in 0..t.len() {
        let w = delassus::<D, N>(t, a, inv, &sets[t.body[a] as usize]);
        t.w[a] = w;
        // W_a ≥ Σ c² M̂⁻¹ > 0: a tie holds movable grains
        t.inv_w[a] = inverse(w).unwrap_or([[0.0; N]; N]);
    }
    make_columns(t, sets);
}

/// The ties' columns ([`TieSet::col`]) when they fit in [`COLUMNS_MAX`] values.
fn make_columns<const N: usize>(t: &mut TieSet<N>, sets: &[NodeSet<N>]) {
    t.col.clear();
    t.col_start.clear();
    let size = |a: usize| N * N * sets[t.body[a] as usize].len();
    if (0..t.len()).map(size).sum::<usize>() > COLUMNS_MAX {
        return;
    }
    t.col_start.push(0);
    for a in 0..t.len() {
        let set = &sets[t.body[a] as usize];
        let nd = N * set.len();
        let at = t.col.len();
        t.col.resize(at + N * nd, 0.0);
        let (nodes, b) = (&t.node[t.nodes(a)], &t.b[t.nodes(a)]);
        for d in 0..N {
            let out = &mut t.col[at + d * nd..at + (d + 1) * nd];
            for (&l, &bl) in nodes.iter().zip(b) {
                let r0 = (N * l as usize + d) * nd;
                for (o, g) in out.iter_mut().zip(&set.g[r0..r0 + nd]) {
                    *o -= bl * g;
                }
            }
        }
        t.col_start.push(t.col.len());
    }
}

/// (‖F(λ)‖², ‖q‖²) of the ties for the natural-map residual: the bilateral law's
/// natural map is u − ū itself, q = u_free − ū. Grain g's velocity at `vel[at(g)]`.
pub fn residual_parts<D: Dim, const N: usize>(
    t: &TieSet<N>,
    sets: &[NodeSet<N>],
    (vel, at): (&[D::Twist], impl Fn(u32) -> usize + Copy),
    ties: impl Iterator<Item = usize>,
) -> (f64, f64) {
    let (mut f2, mut q2) = (0.0, 0.0);
    for a in ties {
        let u = tie_velocity::<D, N>(t, a, (vel, at), &sets[t.body[a] as usize]);
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
