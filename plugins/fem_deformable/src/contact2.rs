//! 2D contacts of deformable bodies: boundary nodes against rigid shapes
//! (node-to-surface through [`nscdd::registry::ShapeStore<D2>::point_contact`]) and
//! against the boundary segments of other deformable bodies (node-to-segment).
//!
//! A contact α has a candidate side, always one boundary node of a deformable body
//! (weight 1), and an antagonist side: a rigid body with its lever arm, or a point
//! of a segment (nodes a, b with weights 1 − ξ, ξ) of another deformable body. The
//! normal n points from the antagonist to the candidate, t = (−n_y, n_x); the local
//! velocity is u = Fᵀ(Σ_k w_k v_k)_cand − (H_jᵀ V_j or Fᵀ Σ_k w_k v_k) with
//! F = [n t]. Node-to-segment is one-sided: the nodes of the body of lower index
//! against the segments of the other (give the finer mesh the lower index).
//!
//! The velocities of the nodes in contact are tracked through the dense block G of
//! M̂⁻¹ among them ([`NodeSet`]): an impulse P at node k changes every contact node
//! l of the same body by G_lk P. The Delassus block of α is
//! W_αα = Σ_kl w_k w_l Fᵀ G_kl F (+ the rigid side's Hᵀ M̂⁻¹ H).

use crate::nodes::FeContacts;
pub use crate::nodes::FeKey;
use nscdd::dd::OwnCells;
use nscdd::dim::d2::Block2;
use nscdd::world::World2;

/// A 2D side: one node, or the two ends of a segment.
pub type FeSide = crate::nodes::FeSide<2>;
/// The contact nodes of one body in 2D (see [`crate::nodes`]).
pub type NodeSet = crate::nodes::NodeSet<2>;

/// The antagonist of a contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Anta {
    /// A rigid body of the world by its global id (on MPI ranks the world's slots
    /// are not the ids; in a subdomain's part, its local copy) and the lever arms
    /// (d × n, d × t).
    Rigid {
        body: u32,
        arm: [f64; 2],
    },
    Fe(FeSide),
}

/// The 2D contacts of deformable bodies of one step; the frame is the normal n.
pub type FeContacts2 = FeContacts<FeSide, Anta, [f64; 2], Block2, 2>;

impl Anta {
    /// The antagonist with its rigid body's id mapped by `at` (a global id to the
    /// world's slot).
    #[inline]
    pub fn rigid_at(self, at: impl Fn(u32) -> usize) -> Anta {
        match self {
            Anta::Rigid { body, arm } => Anta::Rigid {
                body: at(body) as u32,
                arm,
            },
            side => side,
        }
    }

    /// The deformable side, if the antagonist is one.
    #[inline]
    pub fn fe(self) -> Option<FeSide> {
        match self {
            Anta::Fe(s) => Some(s),
            Anta::Rigid { .. } => None,
        }
    }
}

impl NodeSet {
    /// Fᵀ (Σ_kl w_k w_l G_kl) F for a side, as [W_nn, W_nt, W_tt].
    pub fn delassus(&self, s: &FeSide, n: [f64; 2]) -> [f64; 3] {
        let g = self.side_block(s);
        let t = [-n[1], n[0]];
        let q = |a: [f64; 2], b: [f64; 2]| a[0] * (g[0][0] * b[0] + g[0][1] * b[1]) + a[1] * (g[1][0] * b[0] + g[1][1] * b[1]);
        [q(n, n), q(n, t), q(t, t)]
    }
}

/// Local velocity (n, t) of a global vector.
#[inline(always)]
pub fn local(n: [f64; 2], v: [f64; 2]) -> [f64; 2] {
    [n[0] * v[0] + n[1] * v[1], -n[1] * v[0] + n[0] * v[1]]
}
/// Global vector of local impulse components.
#[inline(always)]
pub fn global(n: [f64; 2], r: [f64; 2]) -> [f64; 2] {
    [r[0] * n[0] - r[1] * n[1], r[0] * n[1] + r[1] * n[0]]
}

/// H_jᵀ V_j of a rigid antagonist.
#[inline(always)]
pub fn rigid_local(n: [f64; 2], arm: [f64; 2], v: [f64; 3]) -> [f64; 2] {
    let l = local(n, [v[0], v[1]]);
    [l[0] + arm[0] * v[2], l[1] + arm[1] * v[2]]
}

/// V_j −= M̂_j⁻¹ H_j Δr of a rigid antagonist.
#[inline(always)]
pub fn rigid_apply(n: [f64; 2], arm: [f64; 2], dr: [f64; 2], v: &mut [f64; 3], im: [f64; 3]) {
    let p = global(n, dr);
    v[0] -= im[0] * p[0];
    v[1] -= im[1] * p[1];
    v[2] -= im[2] * (arm[0] * dr[0] + arm[1] * dr[1]);
}

/// H_jᵀ M̂_j⁻¹ H_j of a rigid antagonist: the framework's W_αα with the rigid body
/// as the antagonist and nothing as the candidate.
pub fn rigid_delassus(n: [f64; 2], arm: [f64; 2], im: [f64; 3]) -> [f64; 3] {
    let f = nscdd::dim::d2::Frame2 {
        n,
        arm_i: [0.0; 2],
        arm_j: arm,
    };
    nscdd::dim::d2::delassus(&f, [0.0; 3], im)
}

/// The lever arm (normal, tangential) of a rigid body at `x` for a contact at
/// `point` with normal `n`, t = (−n_y, n_x).
pub fn rigid_arm(n: [f64; 2], point: [f64; 2], x: [f64; 2]) -> [f64; 2] {
    let t = [-n[1], n[0]];
    let d = [point[0] - x[0], point[1] - x[1]];
    [d[0] * n[1] - d[1] * n[0], d[0] * t[1] - d[1] * t[0]]
}

/// Whether a raw contact (its rigid antagonist named by global id) is kept: a
/// law for its materials, and a side that can move along its normal (its node,
/// or its antagonist: W_αα's rigid share, or the segment's nodes). A contact of
/// two fixed sides is dropped at detection, so its nodes join no node set, and
/// every contact kept is built ([`crate::solved::Solved`]).
pub fn kept(w: &World2, bodies: &[crate::body::FeBody], rc: &RawFe) -> bool {
    let (n, body) = (rc.n, &bodies[rc.body as usize]);
    let (moves, material) = match rc.anta {
        RawAnta::Rigid(g) => {
            let ju = crate::family::slot(w, g);
            let wr = rigid_delassus(n, rigid_arm(n, rc.point, w.bodies.pos[ju]), w.bodies.inv_mass[ju]);
            (wr[0] > 0.0, w.bodies.material[ju])
        }
        RawAnta::Segment { body: ob, a, b, xi, .. } => {
            let other = &bodies[ob as usize];
            (other.mobile(&[a, b], &[1.0 - xi, xi], &n), other.material)
        }
    };
    w.law(body.material, material).is_some() && (moves || body.mobile(&[rc.node], &[1.0], &n))
}

/// A contact found by detection, before the node sets exist.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawFe {
    pub body: u32,
    pub node: u32,
    /// Rigid body, or deformable body with segment nodes and ξ.
    pub anta: RawAnta,
    pub n: [f64; 2],
    pub gap: f64,
    pub point: [f64; 2],
    /// The candidate node's position: the contact's point for the partition
    /// ([`nscdd::dd::Attached::points`]), known before the antagonist is searched
    /// (detection in a rank's cells tests it first).
    pub at: [f64; 2],
}

impl RawFe {
    /// [`Self::at`] with z = 0.
    pub fn at3(&self) -> [f64; 3] {
        [self.at[0], self.at[1], 0.0]
    }

    /// Its sides for the rounds of a step stepped in part
    /// ([`crate::solved::Sides`]).
    pub fn sides(&self) -> crate::solved::Sides<2> {
        let cand = (self.body, [self.node; 2]);
        match self.anta {
            RawAnta::Rigid(g) => (cand, None, Some(g)),
            RawAnta::Segment { body, a, b, .. } => (cand, Some((body, [a, b])), None),
        }
    }

    /// The contact's key ([`crate::nodes::FeKey`]: body, node, antagonist — a
    /// rigid body's global id or `1 << 31 |` a deformable body —, segment), once
    /// its rigid antagonist is named by global id; the family's contacts are in
    /// key order (`detect_step`), the same whatever part of the world a rank
    /// holds.
    pub fn key(&self) -> crate::nodes::FeKey {
        match self.anta {
            RawAnta::Rigid(g) => (self.body, self.node, g, 0),
            RawAnta::Segment { body, seg, .. } => (self.body, self.node, 1 << 31 | body, seg),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RawAnta {
    /// A rigid body: its slot in the world from `detect`, its global id once the
    /// family keeps the raw contacts (`detect_step`: slots move on MPI ranks).
    Rigid(u32),
    Segment {
        body: u32,
        seg: u32,
        a: u32,
        b: u32,
        xi: f64,
    },
}

/// Finds node contacts of every deformable body with the rigid bodies of `w`
/// and with the segments of the other deformable bodies, within `alert`; with
/// `own`, those of the nodes in this rank's cells only (a body whose box meets
/// none of them skipped whole).
pub fn detect(w: &World2, fe: &[crate::body::FeBody], alert: f64, own: Option<&OwnCells<'_>>, held: Option<&[bool]>, out: &mut Vec<RawFe>) {
    out.clear();
    // (a body this rank holds stale, [`crate::near`]: an empty box, which meets none)
    let empty = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
    let boxes: Vec<[f64; 4]> = (fe.iter().enumerate())
        .map(|(k, b)| if held.is_none_or(|h| h[k]) { bounds(b) } else { empty })
        .collect();
    let not_own = |p: [f64; 2]| own.is_some_and(|o| !(o.of)([p[0], p[1], 0.0]));
    for (fb, body) in fe.iter().enumerate() {
        let bb = boxes[fb];
        if own.is_some_and(|o| !o.meets(2, &bb[..2], &bb[2..])) {
            continue;
        }
        for rb in 0..w.bodies.len() {
            let s = w.bodies.shape[rb];
            let store = &w.shapes[s.kind as usize];
            let (x, rot) = (w.bodies.pos[rb], w.bodies.rot[rb]);
            let a = store.aabb(s.index, x, rot);
            if !(a.min[0] <= bb[2] + alert && bb[0] <= a.max[0] + alert && a.min[1] <= bb[3] + alert && bb[1] <= a.max[1] + alert) {
                continue;
            }
            if w.law(body.material, w.bodies.material[rb]).is_none() {
                continue;
            }
            for &k in &body.mesh.boundary {
                let p = body.position(k as usize);
                let p = [p[0], p[1]];
                if not_own(p) || p[0] < a.min[0] - alert || p[0] > a.max[0] + alert || p[1] < a.min[1] - alert || p[1] > a.max[1] + alert {
                    continue;
                }
                if let Some(pc) = store.point_contact(s.index, x, rot, p, [0.0; 2]) {
                    if pc.gap <= alert {
                        out.push(RawFe {
                            body: fb as u32,
                            node: k,
                            anta: RawAnta::Rigid(rb as u32),
                            n: pc.normal,
                            gap: pc.gap,
                            point: pc.point,
                            at: p,
                        });
                    }
                }
            }
        }
        // node-to-segment against deformable bodies of higher index
        for (ob, other) in fe.iter().enumerate().skip(fb + 1) {
            let o = boxes[ob];
            if !(o[0] <= bb[2] + alert && bb[0] <= o[2] + alert && o[1] <= bb[3] + alert && bb[1] <= o[3] + alert) {
                continue;
            }
            if w.law(body.material, other.material).is_none() {
                continue;
            }
            for &k in &body.mesh.boundary {
                let p = body.position(k as usize);
                let p = [p[0], p[1]];
                if not_own(p) || p[0] < o[0] - alert || p[0] > o[2] + alert || p[1] < o[1] - alert || p[1] > o[3] + alert {
                    continue;
                }
                if let Some(mut c) = nearest_segment(other, p, alert) {
                    if let RawAnta::Segment { body, .. } = &mut c.0 {
                        *body = ob as u32;
                    }
                    out.push(RawFe {
                        body: fb as u32,
                        node: k,
                        anta: c.0,
                        n: c.1,
                        gap: c.2,
                        point: c.3,
                        at: p,
                    });
                }
            }
        }
    }
}

/// [xmin, ymin, xmax, ymax] of a body's current boundary.
fn bounds(b: &crate::body::FeBody) -> [f64; 4] {
    let mut bb = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
    for &k in &b.mesh.boundary {
        let p = b.position(k as usize);
        bb = [bb[0].min(p[0]), bb[1].min(p[1]), bb[2].max(p[0]), bb[3].max(p[1])];
    }
    bb
}

/// The boundary segment of `b` closest to p with p projecting inside it, within
/// (−segment length, alert]: (antagonist, outward normal, gap, projected point).
fn nearest_segment(b: &crate::body::FeBody, p: [f64; 2], alert: f64) -> Option<(RawAnta, [f64; 2], f64, [f64; 2])> {
    let mut best: Option<(RawAnta, [f64; 2], f64, [f64; 2])> = None;
    for s in 0..b.mesh.n_facets() {
        let f = b.mesh.facet(s);
        let (pa, pb) = (b.position(f[0] as usize), b.position(f[1] as usize));
        let e = [pb[0] - pa[0], pb[1] - pa[1]];
        let l2 = e[0] * e[0] + e[1] * e[1];
        let xi = ((p[0] - pa[0]) * e[0] + (p[1] - pa[1]) * e[1]) / l2;
        if !(0.0..=1.0).contains(&xi) {
            continue;
        }
        let l = l2.sqrt();
        // the body lies on the left of (a, b): outward normal (e_y, −e_x)/|e|
        let n = [e[1] / l, -e[0] / l];
        let q = [pa[0] + xi * e[0], pa[1] + xi * e[1]];
        let gap = (p[0] - q[0]) * n[0] + (p[1] - q[1]) * n[1];
        if gap > alert || gap < -l {
            continue;
        }
        if best.is_none_or(|bst| gap.abs() < bst.2.abs()) {
            best = Some((
                RawAnta::Segment {
                    body: 0,
                    seg: s as u32,
                    a: f[0],
                    b: f[1],
                    xi,
                },
                n,
                gap,
                q,
            ));
        }
    }
    best
}
