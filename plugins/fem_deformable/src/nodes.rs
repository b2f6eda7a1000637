//! The nodes of a deformable body touched by a step's contacts, in any dimension D.
//!
//! A contact side on a deformable body is a point of its boundary written with
//! D node weights ([`FeSide`]): one node (weights (1, 0, …)) for a candidate node,
//! the ends of a segment (2D) or the corners of a triangle (3D) for an antagonist
//! facet. Its velocity is Σ_k w_k v_k and an impulse P applied to it adds w_k P
//! to node k.
//!
//! The velocities of the nodes in contact are tracked through the dense block G
//! of M̂⁻¹ among them ([`NodeSet`]): an impulse P at node k changes every contact
//! node l of the same body by G_lk P, so one NLGS update costs O(n_c) and never
//! solves with M̂. G is filled from columns of M̂⁻¹ ([`crate::body::FeBody::column`],
//! cached while a node stays in contact).

use crate::body::FeBody;

/// One side made of deformable-body nodes: body (index among the deformable
/// bodies), indices of the nodes in that body's [`NodeSet`], weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeSide<const D: usize> {
    pub body: u32,
    pub k: [u32; D],
    pub w: [f64; D],
}

impl<const D: usize> FeSide<D> {
    /// The side of a single node (set index k).
    pub fn node(body: u32, k: u32) -> Self {
        let mut w = [0.0; D];
        w[0] = 1.0;
        FeSide { body, k: [k; D], w }
    }
}

/// Nodes of one body in contact, their current velocities and G
/// (`g[(D k + c) · D n + D l + d]` = entry (c, d) of the block G_kl), scaled by the
/// multiplicity of a copy when the body is shared by subdomains.
#[derive(Debug, Default)]
pub struct NodeSet<const D: usize> {
    pub nodes: Vec<u32>,
    pub v: Vec<[f64; D]>,
    pub g: Vec<f64>,
    /// The nodes `g` holds the blocks of, and the body's [`FeBody::generation`] and
    /// the scale it was filled with ([`fill_set`]).
    g_nodes: Vec<u32>,
    g_of: (u64, f64),
    /// Whether `g_nodes` are `nodes` (else `g` is kept for a later [`fill_set`]
    /// only, and the blocks read as 0).
    g_current: bool,
}

impl<const D: usize> Clone for NodeSet<D> {
    /// The nodes, velocities and current G (a part's copy).
    fn clone(&self) -> Self {
        let g = if self.g_current { self.g.clone() } else { Vec::new() };
        NodeSet {
            nodes: self.nodes.clone(),
            v: self.v.clone(),
            g_nodes: if self.g_current { self.g_nodes.clone() } else { Vec::new() },
            g,
            g_of: self.g_of,
            g_current: self.g_current,
        }
    }
}

impl<const D: usize> NodeSet<D> {
    /// The free velocity at the set's nodes and the rows of G of the nodes `ks`
    /// (`v`: D values a node; `rows`: for each node k of `ks`, the D rows D k + c of
    /// G as [`fill_set`] lays them out), computed by the MPI rank stepping the body
    /// ([`crate::stepped::Stepped::receives`]): the same numbers. The other rows are
    /// 0: this rank reads only those of its contacts' nodes (W_αα's blocks, the
    /// impulses' [`Self::apply`]). Not kept as a cache for a later [`fill_set`].
    /// Wrong lengths or nodes leave G and v at 0 (a rank that failed to step the
    /// body reports it).
    pub fn set_received(&mut self, v: &[f64], ks: &[f64], rows: &[f64]) {
        let n = self.nodes.len();
        let row = D * n;
        let fits = v.len() == row && rows.len() == ks.len() * D * row && ks.iter().all(|&k| k >= 0.0 && (k as usize) < n);
        if !fits {
            debug_assert!(false, "the columns of {n} nodes received as {} values, {} rows", v.len(), ks.len());
            return self.forget_g();
        }
        self.v.clear();
        self.v.extend(v.chunks_exact(D).map(|x| std::array::from_fn(|c| x[c])));
        self.g.clear();
        self.g.resize(D * D * n * n, 0.0);
        for (&k, block) in ks.iter().zip(rows.chunks_exact(D * row)) {
            let at = D * k as usize * row;
            self.g[at..at + D * row].copy_from_slice(block);
        }
        self.g_nodes.clone_from(&self.nodes);
        self.g_of = (u64::MAX, f64::NAN);
        self.g_current = true;
    }

    /// [`Self::set_received`]'s values for the nodes `ks` (set indices, ascending),
    /// appended to `out`: v, the count of `ks`, `ks`, their rows of G.
    pub fn pack_received(&self, ks: &[u32], out: &mut Vec<f64>) {
        let row = D * self.nodes.len();
        out.extend(self.v.iter().flatten());
        out.push(ks.len() as f64);
        out.extend(ks.iter().map(|&k| k as f64));
        for &k in ks {
            let at = D * k as usize * row;
            out.extend_from_slice(&self.g[at..at + D * row]);
        }
    }

    /// G and the velocities at the set's nodes all 0 (not kept as a cache): a body
    /// whose sender failed in the step (which reports it).
    pub fn forget_g(&mut self) {
        let n = self.nodes.len();
        self.v.clear();
        self.v.resize(n, [0.0; D]);
        self.g.clear();
        self.g.resize(D * D * n * n, 0.0);
        self.g_nodes.clone_from(&self.nodes);
        self.g_of = (u64::MAX, f64::NAN);
        self.g_current = true;
    }

    /// Drops G (a body this MPI rank no longer steps,
    /// [`crate::stepped::RELEASE_AFTER`]); the next [`fill_set`] reads every block
    /// from the columns.
    pub fn release_g(&mut self) {
        self.g = Vec::new();
        self.g_nodes.clear();
        self.g_current = false;
    }
    pub fn len(&self) -> usize {
        self.nodes.len()
    }
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }
    /// G_kl.
    #[inline(always)]
    pub fn block(&self, k: usize, l: usize) -> [[f64; D]; D] {
        let nd = D * self.nodes.len();
        let mut b = [[0.0; D]; D];
        for (c, row) in b.iter_mut().enumerate() {
            let r0 = (D * k + c) * nd + D * l;
            row.copy_from_slice(&self.g[r0..r0 + D]);
        }
        b
    }
    /// v_l += G_lk p for every node l of the set (G symmetric: row k is read).
    #[inline(always)]
    pub fn apply(&mut self, k: usize, p: [f64; D]) {
        let nd = D * self.nodes.len();
        for (d, &pd) in p.iter().enumerate() {
            if pd == 0.0 {
                continue;
            }
            let row = &self.g[(D * k + d) * nd..(D * k + d + 1) * nd];
            for (l, v) in self.v.iter_mut().enumerate() {
                for c in 0..D {
                    v[c] += row[D * l + c] * pd;
                }
            }
        }
    }
    /// The velocity of a side: Σ w_k v_k.
    #[inline(always)]
    pub fn side_velocity(&self, s: &FeSide<D>) -> [f64; D] {
        let mut u = [0.0; D];
        for q in 0..D {
            if s.w[q] != 0.0 {
                let v = self.v[s.k[q] as usize];
                for c in 0..D {
                    u[c] += s.w[q] * v[c];
                }
            }
        }
        u
    }
    /// Applies the impulse p (global frame) to a side.
    #[inline(always)]
    pub fn apply_side(&mut self, s: &FeSide<D>, p: [f64; D]) {
        for q in 0..D {
            if s.w[q] != 0.0 {
                self.apply(s.k[q] as usize, p.map(|x| s.w[q] * x));
            }
        }
    }
    /// Σ_kl w_k w_l G_kl: the side's share of the Delassus block (global frame).
    pub fn side_block(&self, s: &FeSide<D>) -> [[f64; D]; D] {
        self.cross_block(s, s)
    }
    /// Σ_kl w_k w'_l G_kl of two sides `a`, `b` of this body (global frame): their
    /// coupling through M̂⁻¹ (`a = b`: [`Self::side_block`]); 0 unless the set's G
    /// holds its current nodes (a body not stepped on this rank, [`fill_nodes`]).
    pub fn cross_block(&self, a: &FeSide<D>, b: &FeSide<D>) -> [[f64; D]; D] {
        let mut g = [[0.0; D]; D];
        if !self.g_current {
            return g;
        }
        for p in 0..D {
            for q in 0..D {
                let ww = a.w[p] * b.w[q];
                if ww != 0.0 {
                    let blk = self.block(a.k[p] as usize, b.k[q] as usize);
                    for c in 0..D {
                        for d in 0..D {
                            g[c][d] += ww * blk[c][d];
                        }
                    }
                }
            }
        }
        g
    }
    /// Adds `sign · w_k p` to the nodal force vector `f` (node-major dofs) of the
    /// body this set belongs to.
    pub fn add_side_force(&self, s: &FeSide<D>, p: [f64; D], sign: f64, f: &mut [f64]) {
        for q in 0..D {
            if s.w[q] != 0.0 {
                let node = self.nodes[s.k[q] as usize] as usize;
                for c in 0..D {
                    f[D * node + c] += sign * s.w[q] * p[c];
                }
            }
        }
    }
}

/// Fills a node set: velocities from the free velocity, G from M̂⁻¹ columns
/// (scaled by `scale`). The blocks between two nodes of the set's last G (built
/// from the same M̂⁻¹, [`FeBody::generation`], and scale) are copied from it:
/// they are these very numbers. Only the blocks of a new node are read from the
/// columns (a read per entry, scattered over columns of the whole mesh), so a
/// body whose contact nodes stay put costs no G a step.
pub fn fill_set<const D: usize>(set: &mut NodeSet<D>, body: &mut FeBody, nodes: &[u32], scale: f64) {
    debug_assert_eq!(body.dim(), D);
    set.v.clear();
    set.v
        .extend(nodes.iter().map(|&k| std::array::from_fn(|c| body.v_free[D * k as usize + c])));
    if set.nodes != nodes {
        set.nodes.clear();
        set.nodes.extend_from_slice(nodes);
    }
    let (n, m) = (nodes.len(), set.g_nodes.len());
    let valid = set.g_of == (body.generation(), scale) && set.g.len() == D * D * m * m;
    set.g_current = true;
    if valid && set.g_nodes == nodes {
        return;
    }
    body.ensure_columns(nodes);
    let nd = body.n_dofs();
    // each node's index in the last G (u32::MAX: new, or nothing kept)
    let was = if valid { old_index(&set.g_nodes, nodes) } else { vec![u32::MAX; n] };
    let old = std::mem::take(&mut set.g);
    set.g.resize(D * D * n * n, 0.0);
    for (k, &ko) in was.iter().enumerate().filter(|x| *x.1 != u32::MAX) {
        for c in 0..D {
            let (row, row_old) = ((D * k + c) * D * n, (D * ko as usize + c) * D * m);
            for (l, &lo) in was.iter().enumerate().filter(|x| *x.1 != u32::MAX) {
                let (a, b) = (row + D * l, row_old + D * lo as usize);
                set.g[a..a + D].copy_from_slice(&old[b..b + D]);
            }
        }
    }
    // G_kl (c, d) = scale · (column d of node l)[D n_k + c] where k or l is new
    let fresh: Vec<usize> = (0..n).filter(|&k| was[k] == u32::MAX).collect();
    let all: Vec<usize> = (0..n).collect();
    for (l, &nl) in nodes.iter().enumerate() {
        let col = body.column(nl);
        let rows = if was[l] == u32::MAX { &all } else { &fresh };
        for d in 0..D {
            let cd = &col[d * nd..(d + 1) * nd];
            for &k in rows {
                for c in 0..D {
                    set.g[(D * k + c) * D * n + D * l + d] = scale * cd[D * nodes[k] as usize + c];
                }
            }
        }
    }
    set.g_nodes.clear();
    set.g_nodes.extend_from_slice(nodes);
    set.g_of = (body.generation(), scale);
}

/// For each node of `new` (sorted), its index in `old` (sorted), or u32::MAX.
fn old_index(old: &[u32], new: &[u32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(new.len());
    let mut i = 0;
    for &x in new {
        while i < old.len() && old[i] < x {
            i += 1;
        }
        out.push(if old.get(i) == Some(&x) { i as u32 } else { u32::MAX });
    }
    out
}

/// A node set of a body this rank does not step ([`crate::stepped`]): its nodes,
/// with zero velocities; its G is kept for a later [`fill_set`] (when the body is
/// stepped here again) but reads as 0 unless it holds these very nodes
/// ([`NodeSet::cross_block`]). Either way its contacts' W_αα are never used here:
/// their parts are not prepared nor swept on this rank.
pub fn fill_nodes<const D: usize>(set: &mut NodeSet<D>, nodes: &[u32]) {
    if set.nodes != nodes {
        set.nodes.clear();
        set.nodes.extend_from_slice(nodes);
    }
    set.g_current = set.g_nodes == set.nodes && !set.g.is_empty();
    set.v.clear();
    set.v.resize(nodes.len(), [0.0; D]);
}

/// The node sets of a step's contact nodes (`nodes` per body, sorted, unique): G
/// and the free velocities of the bodies `stepped` (`None`: all), the nodes alone
/// of the others.
pub fn fill_sets<const D: usize>(bodies: &mut [FeBody], sets: &mut [NodeSet<D>], nodes: &[Vec<u32>], stepped: Option<&[bool]>) {
    for (bi, ns) in nodes.iter().enumerate() {
        let body = &mut bodies[bi];
        body.retain_columns(ns);
        if stepped.is_none_or(|m| m[bi]) {
            fill_set(&mut sets[bi], body, ns, 1.0);
        } else {
            fill_nodes(&mut sets[bi], ns);
        }
    }
}

/// V⁺ = V_free + M̂⁻¹ Σ_α H_α r_α for every body `stepped` (`None`: all): the
/// impulses are (candidate side, deformable antagonist side if any, global
/// impulse P on the candidate); one solve per body touched.
pub fn velocities_after<const D: usize>(
    bodies: &mut [FeBody],
    sets: &[NodeSet<D>],
    impulses: impl Iterator<Item = (FeSide<D>, Option<FeSide<D>>, [f64; D])>,
    stepped: Option<&[bool]>,
) {
    let sides = impulses.flat_map(|(cand, anta, p)| std::iter::once((cand, 1.0, p)).chain(anta.map(|s| (s, -1.0, p))));
    velocities_from(bodies, sets, sides, stepped);
}

/// [`velocities_after`] from the impulses' sides, each (side, sign, P): the
/// side's nodes take sign · P (the one-domain order: the contacts in the
/// family's order, the candidate side before the antagonist).
pub fn velocities_from<const D: usize>(
    bodies: &mut [FeBody],
    sets: &[NodeSet<D>],
    sides: impl Iterator<Item = (FeSide<D>, f64, [f64; D])>,
    stepped: Option<&[bool]>,
) {
    let steps = |b: usize| stepped.is_none_or(|m| m[b]);
    let mut f: Vec<Vec<f64>> = vec![Vec::new(); bodies.len()];
    for (s, sign, p) in sides {
        let b = s.body as usize;
        if !steps(b) {
            continue;
        }
        if f[b].is_empty() {
            f[b] = vec![0.0; bodies[b].n_dofs()];
        }
        sets[b].add_side_force(&s, p, sign, &mut f[b]);
    }
    for (bi, (b, mut dv)) in bodies.iter_mut().zip(f).enumerate() {
        if !steps(bi) {
            continue;
        }
        let mut v = b.v_free.clone();
        if !dv.is_empty() {
            b.solve_in_place(&mut dv);
            for (vi, d) in v.iter_mut().zip(&dv) {
                *vi += d;
            }
        }
        b.v = v;
    }
}

/// Every node set's velocities from its body's V (after the step: V⁺ at the
/// contact nodes, for the residual).
pub fn sets_at_velocities<const D: usize>(bodies: &[FeBody], sets: &mut [NodeSet<D>]) {
    for (b, set) in bodies.iter().zip(sets.iter_mut()) {
        for (v, &nd) in set.v.iter_mut().zip(&set.nodes) {
            *v = std::array::from_fn(|c| b.v[D * nd as usize + c]);
        }
    }
}

/// Identity of a contact between steps (warm start): deformable body, node,
/// antagonist (rigid body id, or `1 << 31 | deformable body`), feature (segment or
/// face).
pub type FeKey = (u32, u32, u32, u32);

/// The contacts of deformable bodies of one step, one `Vec` per field (2D and 3D:
/// sides C and A, frame F, W_αα block B, D components).
#[derive(Clone, Debug)]
pub struct FeContacts<C, A, F, B, const D: usize> {
    pub cand: Vec<C>,
    pub anta: Vec<A>,
    pub frame: Vec<F>,
    pub block: Vec<B>,
    pub target: Vec<nscdd::model::Target>,
    pub r: Vec<[f64; D]>,
    pub u_free: Vec<[f64; D]>,
    pub gap: Vec<f64>,
    pub point: Vec<[f64; D]>,
    pub key: Vec<FeKey>,
}

impl<C, A, F, B, const D: usize> Default for FeContacts<C, A, F, B, D> {
    fn default() -> Self {
        FeContacts {
            cand: vec![],
            anta: vec![],
            frame: vec![],
            block: vec![],
            target: vec![],
            r: vec![],
            u_free: vec![],
            gap: vec![],
            point: vec![],
            key: vec![],
        }
    }
}

impl<C, A, F: Copy, B: Copy, const D: usize> FeContacts<C, A, F, B, D> {
    /// Contact `a`'s results from contact `l` of `part` (a part's write-back).
    pub fn results_from(&mut self, a: usize, part: &Self, l: usize) {
        self.r[a] = part.r[l];
        self.u_free[a] = part.u_free[l];
        self.target[a] = part.target[l];
    }
    pub fn len(&self) -> usize {
        self.cand.len()
    }
    pub fn is_empty(&self) -> bool {
        self.cand.is_empty()
    }
    pub fn clear(&mut self) {
        self.cand.clear();
        self.anta.clear();
        self.frame.clear();
        self.block.clear();
        self.target.clear();
        self.r.clear();
        self.u_free.clear();
        self.gap.clear();
        self.point.clear();
        self.key.clear();
    }
    /// Appends contact `a` of `src` with its sides renamed.
    pub fn push_from(&mut self, src: &Self, a: usize, cand: C, anta: A) {
        self.cand.push(cand);
        self.anta.push(anta);
        self.frame.push(src.frame[a]);
        self.block.push(src.block[a]);
        self.target.push(src.target[a]);
        self.r.push(src.r[a]);
        self.u_free.push(src.u_free[a]);
        self.gap.push(src.gap[a]);
        self.point.push(src.point[a]);
        self.key.push(src.key[a]);
    }
}
