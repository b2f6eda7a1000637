//! 3D contacts of deformable bodies: boundary nodes against rigid shapes
//! (node-to-surface through [`nscdd::registry::ShapeStore<D3>::point_contact`]:
//! spheres, planes, boxes) and against the boundary triangles of other deformable
//! bodies (node-to-face).
//!
//! A contact α has a candidate side on a deformable body, one boundary node or
//! (against rigid kinds that meet faces, [`nscdd::registry::ShapeStore<D3>::meets_faces`]:
//! spheres) the closest point of a boundary triangle, and an antagonist side: a
//! rigid body j with the lever arm d = p − x_j of the contact point, or a point
//! of a boundary triangle (corners a, b, c with barycentric weights) of another
//! deformable body. A sphere smaller than the mesh (radius below the longest
//! boundary edge) meets the body at one point, the closest point of its surface,
//! so that it cannot pass between nodes; larger spheres, planes and boxes meet
//! the boundary nodes (the pressure spreads over the nodes in contact). Several
//! face points per small sphere (one per face in a dent) were tried: faces
//! sharing nodes make a near-singular set of W_αα that NLGS converges on very
//! slowly (thousands of sweeps for one sphere). The frame is the framework's
//! B = [n t1 t2] ([`nscdd::dim::d3::tangents`]), n from the antagonist
//! to the candidate. The local velocity is u = B (Σ_k w_k v_k)_cand − B v_p,j with
//! v_p,j = v_j + ω_j × d (rigid) or Σ_k w_k v_k (deformable), and
//! W_αα = B (Σ_kl w_k w_l G_kl)_cand Bᵀ + (rigid: Bᵀ K_j B, K_j = m⁻¹ + [d]×ᵀ I⁻¹ [d]×;
//! deformable: the same sum over the face). Node-to-face is one-sided: the nodes
//! of the body of lower index against the faces of the other (give the finer
//! mesh the lower index).

use crate::body::FeBody;
pub use crate::nodes::FeKey;
use crate::nodes::{FeContacts, FeSide, NodeSet};
use nscdd::dd::OwnCells;
use nscdd::dim::coulomb3::{self as coulomb, Sym3};
use nscdd::dim::d3::cross;
use nscdd::dim::d3::{point_velocity, Block3, Frame3};
use nscdd::world::World3;

pub type FeSide3 = FeSide<3>;
pub type NodeSet3 = NodeSet<3>;
pub type Basis = [[f64; 3]; 3];

/// The antagonist of a 3D contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Anta3 {
    /// A rigid body of the world by its global id (on MPI ranks the world's slots
    /// are not the ids; in a subdomain's part, its local copy) and the lever arm
    /// d = p − x_j.
    Rigid {
        body: u32,
        d: [f64; 3],
    },
    Fe(FeSide3),
}

impl Anta3 {
    /// The antagonist with its rigid body's id mapped by `at` (a global id to the
    /// world's slot).
    #[inline]
    pub fn rigid_at(self, at: impl Fn(u32) -> usize) -> Anta3 {
        match self {
            Anta3::Rigid { body, d } => Anta3::Rigid { body: at(body) as u32, d },
            side => side,
        }
    }

    /// The deformable side, if the antagonist is one.
    #[inline]
    pub fn fe(self) -> Option<FeSide3> {
        match self {
            Anta3::Fe(s) => Some(s),
            Anta3::Rigid { .. } => None,
        }
    }
}

/// The 3D contacts of deformable bodies of one step; the frame is the basis
/// B = [n t1 t2].
pub type FeContacts3 = FeContacts<FeSide3, Anta3, Basis, Block3, 3>;

/// B v (local components of a global vector).
#[inline(always)]
pub fn local(b: &Basis, v: [f64; 3]) -> [f64; 3] {
    b.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}
/// Bᵀ r (global vector of local components).
#[inline(always)]
pub fn global(b: &Basis, r: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|c| b[0][c] * r[0] + b[1][c] * r[1] + b[2][c] * r[2])
}

/// B G Bᵀ of a global 3×3 block, as the symmetric [w00, w01, w02, w11, w12, w22].
pub fn project(b: &Basis, g: &[[f64; 3]; 3]) -> Sym3 {
    let e = |p: usize, q: usize| {
        let mut s = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                s += b[p][i] * g[i][j] * b[q][j];
            }
        }
        s
    };
    [e(0, 0), e(0, 1), e(0, 2), e(1, 1), e(1, 2), e(2, 2)]
}

/// H_jᵀ V_j of a rigid antagonist: B (v_j + ω_j × d).
#[inline(always)]
pub fn rigid_local(b: &Basis, d: [f64; 3], v: &[f64; 6]) -> [f64; 3] {
    local(b, point_velocity(v, d))
}

/// V_j −= M̂_j⁻¹ H_j Δr of a rigid antagonist.
#[inline(always)]
pub fn rigid_apply(b: &Basis, d: [f64; 3], dr: [f64; 3], v: &mut [f64; 6], inv_m: [f64; 3], inv_i: &Sym3) {
    let p = global(b, dr);
    let w = coulomb::mul(inv_i, cross(d, p));
    for k in 0..3 {
        v[k] -= inv_m[k] * p[k];
        v[3 + k] -= w[k];
    }
}

/// B K_j Bᵀ of a rigid antagonist (the framework's Delassus block with nothing as
/// the candidate).
pub fn rigid_delassus(b: &Basis, d: [f64; 3], inv_m: [f64; 3], inv_i: &Sym3) -> Sym3 {
    let f = Frame3 {
        basis: *b,
        d_i: [0.0; 3],
        d_j: d,
    };
    nscdd::dim::d3::delassus(&f, [0.0; 3], &[0.0; 6], inv_m, inv_i)
}

/// Whether a raw contact (its rigid antagonist named by global id) is kept: a
/// law for its materials, and a side that can move along its normal (its
/// candidate side, or its antagonist: W_αα's rigid share, or the face's nodes).
/// A contact of two fixed sides is dropped at detection, so its nodes join no
/// node set, and every contact kept is built ([`crate::solved::Solved`]).
pub fn kept(w: &World3, bodies: &[FeBody], rc: &RawFe3) -> bool {
    let (n, body) = (&rc.n, &bodies[rc.body as usize]);
    let cand = match rc.cand {
        RawCand3::Node(node) => body.mobile(&[node], &[1.0], n),
        RawCand3::Face { nodes, w: wts, .. } => body.mobile(&nodes, &wts, n),
    };
    let (moves, material) = match rc.anta {
        RawAnta3::Rigid(g) => {
            let ju = crate::family::slot(w, g);
            let x = w.bodies.pos[ju];
            let d = [rc.point[0] - x[0], rc.point[1] - x[1], rc.point[2] - x[2]];
            let (t1, t2) = nscdd::dim::d3::tangents(rc.n);
            let im = &w.bodies.inv_mass[ju];
            (rigid_delassus(&[rc.n, t1, t2], d, im.m, &im.i)[0] > 0.0, w.bodies.material[ju])
        }
        RawAnta3::Face {
            body: ob, nodes, w: wts, ..
        } => {
            let other = &bodies[ob as usize];
            (other.mobile(&nodes, &wts, n), other.material)
        }
    };
    w.law(body.material, material).is_some() && (cand || moves)
}

/// A contact found by detection, before the node sets exist.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawFe3 {
    pub body: u32,
    pub cand: RawCand3,
    pub anta: RawAnta3,
    pub n: [f64; 3],
    pub gap: f64,
    pub point: [f64; 3],
    /// The candidate's point: its node's position, or its face's point at the
    /// weights; the contact's point for the partition
    /// ([`nscdd::dd::Attached::points`]; detection in a rank's cells tests it).
    pub at: [f64; 3],
}

impl RawFe3 {
    /// Its sides for the rounds of a step stepped in part
    /// ([`crate::solved::Sides`]).
    pub fn sides(&self) -> crate::solved::Sides<3> {
        let cand = match self.cand {
            RawCand3::Node(node) => (self.body, [node; 3]),
            RawCand3::Face { nodes, .. } => (self.body, nodes),
        };
        match self.anta {
            RawAnta3::Rigid(g) => (cand, None, Some(g)),
            RawAnta3::Face { body, nodes, .. } => (cand, Some((body, nodes)), None),
        }
    }

    /// The contact's key ([`crate::nodes::FeKey`]: body, node or `1 << 31 |` a
    /// face, antagonist — a rigid body's global id or `1 << 31 |` a deformable
    /// body —, face), once its rigid antagonist is named by global id; the
    /// family's contacts are in key order (`detect_step`), the same whatever part
    /// of the world a rank holds.
    pub fn key(&self) -> crate::nodes::FeKey {
        let cand = match self.cand {
            RawCand3::Node(node) => node,
            RawCand3::Face { face, .. } => 1 << 31 | face,
        };
        match self.anta {
            RawAnta3::Rigid(g) => (self.body, cand, g, 0),
            RawAnta3::Face { body, face, .. } => (self.body, cand, 1 << 31 | body, face),
        }
    }
}

/// The candidate side found by detection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RawCand3 {
    Node(u32),
    /// The closest point of a boundary face (index, corners, weights).
    Face {
        face: u32,
        nodes: [u32; 3],
        w: [f64; 3],
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RawAnta3 {
    /// A rigid body: its slot in the world from `detect`, its global id once the
    /// family keeps the raw contacts (`detect_step`: slots move on MPI ranks).
    Rigid(u32),
    /// A boundary triangle of a deformable body: its index, corners, weights.
    Face {
        body: u32,
        face: u32,
        nodes: [u32; 3],
        w: [f64; 3],
    },
}

type Bounds = ([f64; 3], [f64; 3]);

fn bounds(b: &FeBody) -> Bounds {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &k in &b.mesh.boundary {
        let p = b.position(k as usize);
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    (lo, hi)
}

fn inside(p: [f64; 3], b: &Bounds, margin: f64) -> bool {
    (0..3).all(|c| p[c] >= b.0[c] - margin && p[c] <= b.1[c] + margin)
}

fn overlap(a: &Bounds, b: &Bounds, margin: f64) -> bool {
    (0..3).all(|c| a.0[c] <= b.1[c] + margin && b.0[c] <= a.1[c] + margin)
}

/// The boundary facets and nodes of one deformable body binned in a uniform grid
/// over its box (cells of about two boundary edges, at most 64 per axis), so that
/// a rigid body meets only the facets and nodes near it.
struct SurfaceGrid {
    lo: [f64; 3],
    cell: [f64; 3],
    dims: [usize; 3],
    facets: Vec<Vec<u32>>,
    nodes: Vec<Vec<u32>>,
}

impl SurfaceGrid {
    fn new(body: &FeBody, bb: &Bounds) -> Self {
        let target = 2.0 * body.mesh.longest_boundary_edge;
        let mut dims = [1usize; 3];
        let mut cell = [1.0; 3];
        for c in 0..3 {
            let ext = bb.1[c] - bb.0[c];
            dims[c] = if target > 0.0 {
                ((ext / target).ceil() as usize).clamp(1, 64)
            } else {
                1
            };
            cell[c] = if ext > 0.0 { ext / dims[c] as f64 } else { 1.0 };
        }
        let n = dims[0] * dims[1] * dims[2];
        let mut g = SurfaceGrid {
            lo: bb.0,
            cell,
            dims,
            facets: vec![vec![]; n],
            nodes: vec![vec![]; n],
        };
        for f in 0..body.mesh.n_facets() {
            let v = body.mesh.facet(f);
            let p = [0, 1, 2].map(|c| body.position(v[c] as usize));
            let lo = std::array::from_fn(|c| p[0][c].min(p[1][c]).min(p[2][c]));
            let hi = std::array::from_fn(|c| p[0][c].max(p[1][c]).max(p[2][c]));
            g.each_cell(&(lo, hi), 0.0, |i, g| g.facets[i].push(f as u32));
        }
        for &k in &body.mesh.boundary {
            let p = body.position(k as usize);
            g.each_cell(&(p, p), 0.0, |i, g| g.nodes[i].push(k));
        }
        g
    }

    /// Calls `f` with every cell that the box `b`, grown by `margin`, meets.
    fn each_cell(&mut self, b: &Bounds, margin: f64, mut f: impl FnMut(usize, &mut Self)) {
        let idx = |x: f64, c: usize, s: &Self| (((x - s.lo[c]) / s.cell[c]).floor().max(0.0) as usize).min(s.dims[c] - 1);
        let lo: [usize; 3] = std::array::from_fn(|c| idx(b.0[c] - margin, c, self));
        let hi: [usize; 3] = std::array::from_fn(|c| idx(b.1[c] + margin, c, self));
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    f(x + self.dims[0] * (y + self.dims[1] * z), self);
                }
            }
        }
    }

    /// The facets (`faces`) or boundary nodes near the box `b` grown by `margin`,
    /// in increasing order (the order of a full scan), in `out`.
    fn near(&mut self, b: &Bounds, margin: f64, faces: bool, out: &mut Vec<u32>) {
        out.clear();
        self.each_cell(b, margin, |i, g| {
            out.extend_from_slice(if faces { &g.facets[i] } else { &g.nodes[i] })
        });
        out.sort_unstable();
        out.dedup();
    }
}

/// Finds node contacts of every deformable body with the rigid bodies of `w`
/// and with the boundary faces of the other deformable bodies, within `alert`.
/// Cost: against rigid bodies, the boundary nodes and facets in the grid cells
/// (about two boundary edges wide) that each rigid body's box meets, after a grid
/// built once per body and step; boundary nodes × faces for each pair of
/// deformable bodies whose boxes meet.
///
/// With `own`, only the contacts whose candidate point ([`RawFe3::at`]) lies in
/// this rank's cells (a body whose box meets none of them skipped whole; a face
/// contact chosen among all the faces first, as whole detection chooses it).
pub fn detect(w: &World3, fe: &[FeBody], alert: f64, own: Option<&OwnCells<'_>>, held: Option<&[bool]>, out: &mut Vec<RawFe3>) {
    out.clear();
    // (a body this rank holds stale, [`crate::near`]: an empty box, which meets none)
    let empty = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let boxes: Vec<Bounds> = (fe.iter().enumerate())
        .map(|(k, b)| if held.is_none_or(|h| h[k]) { bounds(b) } else { empty })
        .collect();
    let mut near: Vec<u32> = vec![];
    let is_own = |p: [f64; 3]| own.is_none_or(|o| (o.of)(p));
    for (fb, body) in fe.iter().enumerate() {
        let bb = boxes[fb];
        if own.is_some_and(|o| !o.meets(3, &bb.0, &bb.1)) {
            continue;
        }
        let mut grid: Option<SurfaceGrid> = None;
        for rb in 0..w.bodies.len() {
            let s = w.bodies.shape[rb];
            let store = &w.shapes[s.kind as usize];
            let (x, q) = (w.bodies.pos[rb], w.bodies.rot[rb]);
            let a = store.aabb(s.index, x, q);
            let ab = (a.min, a.max);
            if !overlap(&ab, &bb, alert) || w.law(body.material, w.bodies.material[rb]).is_none() {
                continue;
            }
            let grid = grid.get_or_insert_with(|| SurfaceGrid::new(body, &bb));
            if store.meets_faces() && store.size(s.index) < body.mesh.longest_boundary_edge {
                // one contact at the surface's closest point: several points of
                // neighbouring faces sharing nodes make a near-singular W_αα set
                // that NLGS converges on very slowly
                let mut best: Option<RawFe3> = None;
                grid.near(&ab, alert, true, &mut near);
                for &f in &near {
                    let f = f as usize;
                    let nodes = body.mesh.facet(f);
                    let tri = [0, 1, 2].map(|c| body.position(nodes[c] as usize));
                    let fb3 = (
                        std::array::from_fn(|c| tri[0][c].min(tri[1][c]).min(tri[2][c])),
                        std::array::from_fn(|c| tri[0][c].max(tri[1][c]).max(tri[2][c])),
                    );
                    if !overlap(&fb3, &ab, alert) {
                        continue;
                    }
                    let Some(fc) = store.face_contact(s.index, x, q, &tri) else {
                        continue;
                    };
                    if fc.gap > alert {
                        continue;
                    }
                    let rc = RawFe3 {
                        body: fb as u32,
                        cand: RawCand3::Face {
                            face: f as u32,
                            nodes: [nodes[0], nodes[1], nodes[2]],
                            w: fc.bary,
                        },
                        anta: RawAnta3::Rigid(rb as u32),
                        // from the antagonist (the rigid shape) to the candidate
                        n: fc.normal,
                        gap: fc.gap,
                        point: fc.point,
                        at: std::array::from_fn(|c| (0..3).map(|k| fc.bary[k] * tri[k][c]).sum()),
                    };
                    if best.is_none_or(|b| fc.gap < b.gap) {
                        best = Some(rc);
                    }
                }
                out.extend(best.filter(|b| is_own(b.at)));
                continue;
            }
            grid.near(&ab, alert, false, &mut near);
            for &k in &near {
                let p = body.position(k as usize);
                if !inside(p, &ab, alert) || !is_own(p) {
                    continue;
                }
                if let Some(pc) = store.point_contact(s.index, x, q, p, body.mesh.node_normal[k as usize]) {
                    if pc.gap <= alert {
                        out.push(RawFe3 {
                            body: fb as u32,
                            cand: RawCand3::Node(k),
                            anta: RawAnta3::Rigid(rb as u32),
                            n: pc.normal,
                            gap: pc.gap,
                            point: pc.point,
                            at: p,
                        });
                    }
                }
            }
        }
        fe_pairs(w, fe, (&boxes, fb, alert), &is_own, out);
    }
}

/// Node contacts of deformable body `fb`'s boundary nodes with the boundary faces of
/// the deformable bodies after it whose boxes meet its own.
/// `own`: whether a node's position is this rank's.
fn fe_pairs(w: &World3, fe: &[FeBody], (boxes, fb, alert): (&[Bounds], usize, f64), own: &dyn Fn([f64; 3]) -> bool, out: &mut Vec<RawFe3>) {
    let (body, bb) = (&fe[fb], boxes[fb]);
    for (ob, other) in fe.iter().enumerate().skip(fb + 1) {
        let o = boxes[ob];
        if !overlap(&o, &bb, alert) || w.law(body.material, other.material).is_none() {
            continue;
        }
        for &k in &body.mesh.boundary {
            let p = body.position(k as usize);
            if !inside(p, &o, alert) || !own(p) {
                continue;
            }
            if let Some((face, nodes, wts, n, gap, q)) = nearest_face(other, p, alert) {
                out.push(RawFe3 {
                    body: fb as u32,
                    cand: RawCand3::Node(k),
                    anta: RawAnta3::Face {
                        body: ob as u32,
                        face,
                        nodes,
                        w: wts,
                    },
                    n,
                    gap,
                    point: q,
                    at: p,
                });
            }
        }
    }
}

type FaceHit = (u32, [u32; 3], [f64; 3], [f64; 3], f64, [f64; 3]);

/// The boundary triangle of `b` closest to p with p projecting inside it, within
/// (−edge length, alert]: (face, corners, barycentric weights, outward normal,
/// gap, projected point).
fn nearest_face(b: &FeBody, p: [f64; 3], alert: f64) -> Option<FaceHit> {
    let mut best: Option<FaceHit> = None;
    for s in 0..b.mesh.n_facets() {
        let f = b.mesh.facet(s);
        let (pa, pb, pc) = (b.position(f[0] as usize), b.position(f[1] as usize), b.position(f[2] as usize));
        let e1 = sub(pb, pa);
        let e2 = sub(pc, pa);
        let nn = cross(e1, e2);
        let area2 = dot(nn, nn).sqrt();
        if area2 == 0.0 {
            continue;
        }
        let n = nn.map(|x| x / area2);
        let ap = sub(p, pa);
        let gap = dot(ap, n);
        let size = dot(e1, e1).sqrt().max(dot(e2, e2).sqrt());
        if gap > alert || gap < -size {
            continue;
        }
        // barycentric coordinates of the projection
        let (d11, d12, d22) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
        let (d1p, d2p) = (dot(e1, ap), dot(e2, ap));
        let det = d11 * d22 - d12 * d12;
        let xi = (d22 * d1p - d12 * d2p) / det;
        let eta = (d11 * d2p - d12 * d1p) / det;
        let tol = -1e-12;
        if xi < tol || eta < tol || xi + eta > 1.0 - tol {
            continue;
        }
        if best.is_none_or(|bst| gap.abs() < bst.4.abs()) {
            let q = [
                pa[0] + xi * e1[0] + eta * e2[0],
                pa[1] + xi * e1[1] + eta * e2[1],
                pa[2] + xi * e1[2] + eta * e2[2],
            ];
            best = Some((s as u32, [f[0], f[1], f[2]], [1.0 - xi - eta, xi, eta], n, gap, q));
        }
    }
    best
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
