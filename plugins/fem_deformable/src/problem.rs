//! The deformable contacts' share of a step's local problem (`nscdd export-fc`,
//! [`nscdd::fc::FamilyShare`]), in 2D and 3D.
//!
//! For contact α with local frame rows R_α (n, t in 2D; n, t1, t2 in 3D), sides
//! s ∈ α on deformable bodies (the candidate node, sign σ = +1; a facet antagonist,
//! σ = −1; node weights w_k) and a rigid antagonist j (σ = −1):
//!
//! ```text
//! q_α   = u_free,α − ū e_n
//! H_jᵀ  = −R_α [I | (d ×)ᵀ]          (the rows of the rigid antagonist; 2D: arms)
//! W_αβ += σ_s σ_s' R_α (Σ_kl w_k w_l G_kl) R_βᵀ     sides s ∈ α, s' ∈ β on one body
//! ```
//!
//! with G the block of M̂⁻¹ among the body's contact nodes ([`crate::nodes::NodeSet`]):
//! the same numbers the solve used (its W_αα are these blocks plus the rigid part).

use crate::nodes::{FeContacts, FeSide, NodeSet};
use nscdd::fc::FamilyShare;

/// R a Rᵀ-like product: R_α m R_βᵀ (m global D × D).
fn sandwich<const D: usize>(ra: &[[f64; D]; D], m: &[[f64; D]; D], rb: &[[f64; D]; D]) -> Vec<f64> {
    let mut out = vec![0.0; D * D];
    for p in 0..D {
        for q in 0..D {
            let mut s = 0.0;
            for c in 0..D {
                for d in 0..D {
                    s += ra[p][c] * m[c][d] * rb[q][d];
                }
            }
            out[D * p + q] = s;
        }
    }
    out
}

/// What the share needs of one dimension's contacts.
pub struct Dims<'a, A, F, const D: usize> {
    /// The local frame rows of a contact.
    pub rows: &'a dyn Fn(&F) -> [[f64; D]; D],
    /// The deformable side of an antagonist, if it is one.
    pub anta_fe: &'a dyn Fn(&A) -> Option<FeSide<D>>,
    /// A rigid antagonist's body and H_jᵀ rows (row-major, sign included).
    pub rigid: &'a dyn Fn(&A, &F) -> Option<(u32, Vec<f64>)>,
}

/// The share of the contacts `c` (their node sets `sets`), rigid rows only on
/// `movable` bodies.
pub fn share<A: Copy, F: Copy, B: Copy, const D: usize>(
    c: &FeContacts<FeSide<D>, A, F, B, D>,
    sets: &[NodeSet<D>],
    dims: Dims<'_, A, F, D>,
    movable: impl Fn(u32) -> bool,
) -> FamilyShare {
    let n = c.len();
    let mut s = FamilyShare::default();
    for a in 0..n {
        let (uf, t) = (c.u_free[a], c.target[a]);
        s.q.extend((0..D).map(|k| if k == 0 { uf[0] - t.u_target } else { uf[k] }));
        s.mu.push(t.mu);
        if let Some((body, rows)) = (dims.rigid)(&c.anta[a], &c.frame[a]) {
            if movable(body) {
                s.rigid.push((a as u32, body, rows));
            }
        }
    }
    // the deformable sides of each contact, with their signs
    let sides: Vec<Vec<(FeSide<D>, f64)>> = (0..n)
        .map(|a| {
            let mut v = vec![(c.cand[a], 1.0)];
            v.extend((dims.anta_fe)(&c.anta[a]).map(|x| (x, -1.0)));
            v
        })
        .collect();
    let rows: Vec<[[f64; D]; D]> = c.frame.iter().map(|f| (dims.rows)(f)).collect();
    for a in 0..n {
        for b in a..n {
            let mut m = [[0.0; D]; D];
            let mut touched = false;
            for (sa, ga) in &sides[a] {
                for (sb, gb) in &sides[b] {
                    if sa.body != sb.body {
                        continue;
                    }
                    let g = sets[sa.body as usize].cross_block(sa, sb);
                    for p in 0..D {
                        for q in 0..D {
                            m[p][q] += ga * gb * g[p][q];
                        }
                    }
                    touched = true;
                }
            }
            if touched {
                s.own.push((a as u32, b as u32, sandwich(&rows[a], &m, &rows[b])));
            }
        }
    }
    s
}

/// The 2D deformable contacts' share.
pub fn share2(fe: &crate::stage2::Deformables2, w: &nscdd::world::World2) -> FamilyShare {
    use crate::contact2::Anta;
    let rows = |n: &[f64; 2]| [[n[0], n[1]], [-n[1], n[0]]];
    let anta_fe = |a: &Anta| a.fe();
    let rigid = |a: &Anta, n: &[f64; 2]| match a {
        Anta::Rigid { body, arm } => Some((*body, vec![-n[0], -n[1], -arm[0], n[1], -n[0], -arm[1]])),
        Anta::Fe(_) => None,
    };
    let dims = Dims {
        rows: &rows,
        anta_fe: &anta_fe,
        rigid: &rigid,
    };
    share(&fe.contacts, &fe.sets, dims, |b| w.bodies.movable(b as usize))
}

/// The 3D deformable contacts' share.
pub fn share3(fe: &crate::stage3::Deformables3, w: &nscdd::world::World3) -> FamilyShare {
    use crate::contact3::{Anta3, Basis};
    use nscdd::dim::d3::cross;
    let rows = |b: &Basis| *b;
    let anta_fe = |a: &Anta3| a.fe();
    let rigid = |a: &Anta3, b: &Basis| match a {
        Anta3::Rigid { body, d } => {
            let mut rows = Vec::with_capacity(18);
            for e in b {
                let m = cross(*d, *e);
                rows.extend([-e[0], -e[1], -e[2], -m[0], -m[1], -m[2]]);
            }
            Some((*body, rows))
        }
        Anta3::Fe(_) => None,
    };
    let dims = Dims {
        rows: &rows,
        anta_fe: &anta_fe,
        rigid: &rigid,
    };
    share(&fe.contacts, &fe.sets, dims, |b| w.bodies.movable(b as usize))
}
