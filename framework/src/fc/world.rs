//! The local problem of a 2D world's last step, in the exchange format.

use super::{CooMatrix, FcProblem};
use crate::world::World2;

/// A body family's share of the step's local problem ([`crate::family::SceneFamily::local_problem`]),
/// its contacts numbered 0.. (after the world's and the earlier families' in the
/// problem): per contact d values of q = u_free − ū e_n and μ; each contact's H_bᵀ
/// on the world's movable rigid bodies b (d rows of the body's dofs, row-major); and
/// the blocks W_αβ (α ≤ β, d × d row-major) through the family's own bodies.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FamilyShare {
    pub q: Vec<f64>,
    pub mu: Vec<f64>,
    /// (contact, rigid body, H_bᵀ rows).
    pub rigid: Vec<(u32, u32, Vec<f64>)>,
    /// (α, β, W_αβ) with α ≤ β.
    pub own: Vec<(u32, u32, Vec<f64>)>,
}

/// The families' contacts' H_bᵀ rows, as (body, contact, rows) in the problem's
/// numbering (`off`: each family's first contact), and their own blocks as
/// (α, β, block); `rows`/`block` turn the flat values into the dimension's arrays.
fn family_parts<H, B>(
    shares: &[FamilyShare],
    off: &[usize],
    rows: impl Fn(&[f64]) -> H,
    block: impl Fn(&[f64]) -> B,
) -> (Vec<(u32, u32, H)>, Vec<(u32, u32, B)>) {
    let (mut inc, mut own) = (vec![], vec![]);
    for (s, &o) in shares.iter().zip(off) {
        let at = |a: u32| (o + a as usize) as u32;
        inc.extend(s.rigid.iter().map(|(a, body, h)| (*body, at(*a), rows(h))));
        own.extend(s.own.iter().map(|(x, y, b)| (at(*x), at(*y), block(b))));
    }
    (inc, own)
}

/// The 3 × 3 block contributions (α ≤ β) summed per pair and written as the
/// symmetric matrix's triplets, block pair by block pair (α, β) then (β, α).
fn triplets3(mut contrib: Vec<(u32, u32, [[f64; 3]; 3])>) -> Vec<(usize, usize, f64)> {
    contrib.sort_by_key(|x| (x.0, x.1));
    let mut trip: Vec<(usize, usize, f64)> = Vec::with_capacity(9 * contrib.len());
    let mut k = 0;
    while k < contrib.len() {
        let (ca, cb, mut blk) = contrib[k];
        k += 1;
        while k < contrib.len() && (contrib[k].0, contrib[k].1) == (ca, cb) {
            for p in 0..3 {
                for q in 0..3 {
                    blk[p][q] += contrib[k].2[p][q];
                }
            }
            k += 1;
        }
        let (ra, rb) = (3 * ca as usize, 3 * cb as usize);
        for p in 0..3 {
            for q in 0..3 {
                trip.push((ra + p, rb + q, blk[p][q]));
                if ca != cb {
                    trip.push((rb + q, ra + p, blk[p][q]));
                }
            }
        }
    }
    trip
}

/// The families' contact offsets, q and μ after the world's `nw` contacts.
fn family_rows(nw: usize, d: usize, shares: &[FamilyShare]) -> (Vec<usize>, Vec<f64>, Vec<f64>) {
    let mut off = vec![];
    let (mut q, mut mu) = (vec![], vec![]);
    let mut at = nw;
    for s in shares {
        off.push(at);
        at += s.mu.len();
        q.extend_from_slice(&s.q);
        mu.extend_from_slice(&s.mu);
    }
    debug_assert_eq!(q.len(), d * (at - nw));
    (off, q, mu)
}

/// The local problem of the last step of a 2D world (call it right after
/// [`World2::step`]): W = Hᵀ M̂⁻¹ H over `w.contacts` and q = u_free − ū e_n. The
/// impulses the world found, `w.contacts.r`, are an (approximate) solution of it.
pub fn problem_from_world(w: &World2) -> FcProblem {
    problem_with(w, &[])
}

/// [`problem_from_world`] with the body families' shares (their contacts after the
/// world's).
pub fn problem_with(w: &World2, shares: &[FamilyShare]) -> FcProblem {
    let c = &w.contacts;
    let b = &w.bodies;
    let nw = c.len();
    let (off, fq, fmu) = family_rows(nw, 2, shares);
    let nc = nw + fmu.len();
    // H_bᵀ (2 × 3) of contact a seen from body b, with its sign.
    let h_of = |a: usize, arm: [f64; 2], s: f64| {
        let n = c.frame[a].n;
        [[s * n[0], s * n[1], s * arm[0]], [-s * n[1], s * n[0], s * arm[1]]]
    };
    // (body, contact, H_bᵀ) for the bodies impulses can move, grouped by body.
    let mut inc: Vec<(u32, u32, [[f64; 3]; 2])> = Vec::with_capacity(2 * nc);
    for a in 0..nw {
        let [i, j] = c.bodies[a];
        if b.movable(i as usize) {
            inc.push((i, a as u32, h_of(a, c.frame[a].arm_i, 1.0)));
        }
        if b.movable(j as usize) {
            inc.push((j, a as u32, h_of(a, c.frame[a].arm_j, -1.0)));
        }
    }
    let (finc, mut contrib) = family_parts(
        shares,
        &off,
        |h| [[h[0], h[1], h[2]], [h[3], h[4], h[5]]],
        |b| [b[0], b[1], b[2], b[3]],
    );
    inc.extend(finc);
    inc.sort_unstable_by_key(|x| (x.0, x.1)); // (body, contact): unique keys
                                              // Contributions to the blocks (α ≤ β) from each shared body (and the families' own).
    for c in contrib.iter_mut().filter(|c| c.0 == c.1) {
        c.2[2] = c.2[1];
    }
    if c.compliant {
        let compliant = c.compliance.iter().enumerate().filter(|x| *x.1 > 0.0);
        contrib.extend(compliant.map(|(a, &cc)| (a as u32, a as u32, [cc, 0.0, 0.0, 0.0])));
    }
    let mut g0 = 0;
    while g0 < inc.len() {
        let body = inc[g0].0;
        let g1 = g0 + inc[g0..].iter().take_while(|x| x.0 == body).count();
        let m = b.inv_mass[body as usize];
        for x in g0..g1 {
            for y in x..g1 {
                let ((_, ca, ha), (_, cb, hb)) = (inc[x], inc[y]);
                let e = |p: usize, q: usize| (0..3).map(|k| ha[p][k] * m[k] * hb[q][k]).sum::<f64>();
                let mut blk = [e(0, 0), e(0, 1), e(1, 0), e(1, 1)];
                if ca == cb {
                    blk[2] = blk[1];
                }
                contrib.push((ca, cb, blk));
            }
        }
        g0 = g1;
    }
    contrib.sort_by_key(|x| (x.0, x.1));
    let mut trip: Vec<(usize, usize, f64)> = Vec::with_capacity(4 * contrib.len());
    let mut k = 0;
    while k < contrib.len() {
        let (ca, cb, mut blk) = contrib[k];
        k += 1;
        while k < contrib.len() && (contrib[k].0, contrib[k].1) == (ca, cb) {
            for (x, y) in blk.iter_mut().zip(contrib[k].2) {
                *x += y;
            }
            k += 1;
        }
        let (ra, rb) = (2 * ca as usize, 2 * cb as usize);
        for (s, v) in blk.iter().enumerate() {
            trip.push((ra + s / 2, rb + s % 2, *v));
            if ca != cb {
                trip.push((rb + s % 2, ra + s / 2, *v));
            }
        }
    }
    let mut q = Vec::with_capacity(2 * nc);
    for a in 0..nw {
        q.push(c.u_free[a][0] - c.target[a].u_target);
        q.push(c.u_free[a][1]);
    }
    q.extend(fq);
    let meta = serde_json::json!({
        "source": format!("nscdd: 2D world after step {} (t = {} s), {} bodies", w.step, w.t, b.len()),
    });
    FcProblem {
        dim: 2,
        nc,
        w: CooMatrix::from_triplets(2 * nc, &trip),
        q,
        mu: c.target.iter().map(|t| t.mu).chain(fmu).collect(),
        meta: Some(meta),
    }
}

/// The local problem of the last step of a 3D world (call it right after
/// [`crate::world::World3::step`]): with `H_bᵀ` (3 × 6) of contact α seen from body b,
/// rows `(e_k, d_b × e_k)` for the frame vectors e_k = n, t1, t2 (+ for the candidate,
/// − for the antagonist), `W_αβ = Σ_b H_bαᵀ M̂_b⁻¹ H_bβ` with `M̂_b⁻¹ = diag(m⁻¹) ⊕
/// I_w⁻¹`, and `q_α = (u_free,n − ū, u_free,t1, u_free,t2)`.
pub fn problem_from_world3(w: &crate::world::World3) -> FcProblem {
    problem_with3(w, &[])
}

/// [`problem_from_world3`] with the body families' shares (their contacts after the
/// world's).
pub fn problem_with3(w: &crate::world::World3, shares: &[FamilyShare]) -> FcProblem {
    use crate::dim::d3::cross;
    let c = &w.contacts;
    let b = &w.bodies;
    let nw = c.len();
    let (off, fq, fmu) = family_rows(nw, 3, shares);
    let nc = nw + fmu.len();
    let h_of = |a: usize, d: [f64; 3], s: f64| -> [[f64; 6]; 3] {
        let f = &c.frame[a];
        std::array::from_fn(|k| {
            let e = f.basis[k];
            let m = cross(d, e);
            [s * e[0], s * e[1], s * e[2], s * m[0], s * m[1], s * m[2]]
        })
    };
    let mut inc: Vec<(u32, u32, [[f64; 6]; 3])> = Vec::with_capacity(2 * nc);
    for a in 0..nw {
        let [i, j] = c.bodies[a];
        if b.movable(i as usize) {
            inc.push((i, a as u32, h_of(a, c.frame[a].d_i, 1.0)));
        }
        if b.movable(j as usize) {
            inc.push((j, a as u32, h_of(a, c.frame[a].d_j, -1.0)));
        }
    }
    let rows = |h: &[f64]| -> [[f64; 6]; 3] { std::array::from_fn(|k| std::array::from_fn(|l| h[6 * k + l])) };
    let block = |v: &[f64]| -> [[f64; 3]; 3] { std::array::from_fn(|p| std::array::from_fn(|q| v[3 * p + q])) };
    let (finc, mut contrib) = family_parts(shares, &off, rows, block);
    if c.compliant {
        let compliant = c.compliance.iter().enumerate().filter(|x| *x.1 > 0.0);
        let diag = |cc: f64| std::array::from_fn(|p| std::array::from_fn(|q| if p + q == 0 { cc } else { 0.0 }));
        contrib.extend(compliant.map(|(a, &cc)| (a as u32, a as u32, diag(cc))));
    }
    inc.extend(finc);
    inc.sort_unstable_by_key(|x| (x.0, x.1)); // (body, contact): unique keys
    let mut g0 = 0;
    while g0 < inc.len() {
        let body = inc[g0].0 as usize;
        let g1 = g0 + inc[g0..].iter().take_while(|x| x.0 as usize == body).count();
        let (im, ii) = (b.inv_mass[body].m, b.inv_mass[body].i);
        // M̂⁻¹ h for a row h of Hᵀ
        let minv = |h: &[f64; 6]| -> [f64; 6] {
            let w = crate::dim::coulomb3::mul(&ii, [h[3], h[4], h[5]]);
            [im[0] * h[0], im[1] * h[1], im[2] * h[2], w[0], w[1], w[2]]
        };
        for x in g0..g1 {
            for y in x..g1 {
                let ((_, ca, ha), (_, cb, hb)) = (inc[x], inc[y]);
                let blk: [[f64; 3]; 3] = std::array::from_fn(|p| {
                    let mp = minv(&ha[p]);
                    std::array::from_fn(|q| (0..6).map(|k| mp[k] * hb[q][k]).sum::<f64>())
                });
                contrib.push((ca, cb, blk));
            }
        }
        g0 = g1;
    }
    let trip = triplets3(contrib);
    let mut q = Vec::with_capacity(3 * nc);
    for a in 0..nw {
        q.push(c.u_free[a][0] - c.target[a].u_target);
        q.push(c.u_free[a][1]);
        q.push(c.u_free[a][2]);
    }
    q.extend(fq);
    let meta = serde_json::json!({
        "source": format!("nscdd: 3D world after step {} (t = {} s), {} bodies", w.step, w.t, b.len()),
    });
    FcProblem {
        dim: 3,
        nc,
        w: CooMatrix::from_triplets(3 * nc, &trip),
        q,
        mu: c.target.iter().map(|t| t.mu).chain(fmu).collect(),
        meta: Some(meta),
    }
}

/// The local problem of the current step of a world of either dimension, the
/// families' shares after the world's contacts.
pub fn problem_of<D: crate::dim::Dim>(w: &crate::world::World<D>, shares: &[FamilyShare]) -> FcProblem {
    let any = w as &dyn std::any::Any;
    match (
        any.downcast_ref::<crate::world::World2>(),
        any.downcast_ref::<crate::world::World3>(),
    ) {
        (Some(w2), _) => problem_with(w2, shares),
        (_, Some(w3)) => problem_with3(w3, shares),
        _ => unreachable!("Dim is sealed: D2 or D3"),
    }
}

/// The contact stage of `[solver] method = "newton"`: W of the step's contacts assembled from their frames and the bodies' M̂⁻¹
/// ([`problem_of`]), solved from the warm start (the contacts' r, already applied
/// to the bodies) with the scene's norm, tolerance, iteration limit and check
/// period; then V += M̂⁻¹ H (r − r_warm) contact by contact.
pub fn solve_world<D: crate::dim::Dim>(w: &mut crate::world::World<D>) -> crate::solver::SolveReport {
    use crate::dim::Vector;
    let p = problem_of(w, &[]);
    let s = &w.solver;
    let opts = super::FcOptions {
        tol: s.tolerance,
        max_sweeps: s.max_sweeps,
        check_every: s.check_every,
        norm: super::FcNorm::Lmgc(s.norm),
        method: s.method,
        relaxation: s.relaxation,
    };
    let c = &mut w.contacts;
    let r0: Vec<f64> = c.r.iter().flat_map(|r| r.as_ref().iter().copied()).collect();
    let sol = p.solve_from(Some(&r0), &opts);
    let d = <D::Local as Vector>::LEN;
    for a in 0..c.len() {
        let r = <D::Local as Vector>::from_fn(|k| sol.r[d * a + k]);
        let dr = r.sub(&c.r[a]);
        c.apply(a, &dr, &mut w.bodies.vel, &w.bodies.inv_mass);
        c.r[a] = r;
    }
    crate::solver::SolveReport {
        sweeps: sol.sweeps,
        converged: sol.converged,
        norms: sol.norms,
        residual: sol.residual,
    }
}
