//! The local problem of a 2D world's last step, in the exchange format.

use super::{CooMatrix, FcProblem};
use crate::world::World2;

/// The local problem of the last step of a 2D world (call it right after
/// [`World2::step`]): W = Hᵀ M̂⁻¹ H over `w.contacts` and q = u_free − ū e_n. The
/// impulses the world found, `w.contacts.r`, are an (approximate) solution of it.
pub fn problem_from_world(w: &World2) -> FcProblem {
    let c = &w.contacts;
    let b = &w.bodies;
    let nc = c.len();
    // H_bᵀ (2 × 3) of contact a seen from body b, with its sign.
    let h_of = |a: usize, arm: [f64; 2], s: f64| {
        let n = c.frame[a].n;
        [[s * n[0], s * n[1], s * arm[0]], [-s * n[1], s * n[0], s * arm[1]]]
    };
    // (body, contact, H_bᵀ) for the bodies impulses can move, grouped by body.
    let mut inc: Vec<(u32, u32, [[f64; 3]; 2])> = Vec::with_capacity(2 * nc);
    for a in 0..nc {
        let [i, j] = c.bodies[a];
        if b.movable(i as usize) {
            inc.push((i, a as u32, h_of(a, c.frame[a].arm_i, 1.0)));
        }
        if b.movable(j as usize) {
            inc.push((j, a as u32, h_of(a, c.frame[a].arm_j, -1.0)));
        }
    }
    inc.sort_by_key(|x| (x.0, x.1));
    // Contributions to the blocks (α ≤ β) from each shared body.
    let mut contrib: Vec<(u32, u32, [f64; 4])> = Vec::new();
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
    trip.sort_by_key(|x| (x.0, x.1));
    let mut q = Vec::with_capacity(2 * nc);
    for a in 0..nc {
        q.push(c.u_free[a][0] - c.target[a].u_target);
        q.push(c.u_free[a][1]);
    }
    let meta = serde_json::json!({
        "source": format!("nscdd: 2D world after step {} (t = {} s), {} bodies", w.step, w.t, b.len()),
    });
    FcProblem {
        dim: 2,
        nc,
        w: CooMatrix::from_triplets(2 * nc, &trip),
        q,
        mu: c.target.iter().map(|t| t.mu).collect(),
        meta: Some(meta),
    }
}
