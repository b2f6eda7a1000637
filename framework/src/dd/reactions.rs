//! The per-body reactions Σ ±H r of an NSCDD step, computed subdomain by
//! subdomain: each subdomain's share over its own contacts (in their order), the
//! shares added in subdomain order. Whoever holds a subdomain can compute its share,
//! so on MPI ranks the observed bodies' reactions (named or driven bodies: outputs
//! and servo drives read them) are exact and the same on every rank whatever the
//! number of ranks, from one all-gather of the own subdomains' shares of those
//! bodies ([`RankState::share_reactions`]). A body that is not observed gets the
//! shares of this rank's subdomains only.
//!
//! ```text
//! R_b = Σ_E (in subdomain order) Σ_{α ∈ E, α touches b} ±H_α r_α
//! ```

use super::family::Family;
use super::partition::Decomposition;
use super::ranks::RankState;

/// Sets the world's reactions ([`Family::set_reactions`]) from the subdomains of
/// `d` (see the module docs).
pub(super) fn set<D: Family>(d: &Decomposition<D>, w: &mut D::World, ranks: Option<&mut RankState>, observed: &[u32]) {
    // by slot: a subdomain's bodies on this rank are held here (its own, and the
    // observed bodies of the others, which every rank steps)
    let slots = D::held(w).map_or(D::n_bodies(w), <[u32]>::len);
    let slot = |g: u32| D::held_slot(w, g as usize);
    let own = |s: u32| ranks.as_ref().is_none_or(|r| r.is_own(s));
    // each own subdomain's share, by local body
    let shares: Vec<Vec<D::V>> = d
        .subs
        .iter()
        .map(|s| {
            let mut share = Vec::new();
            if own(s.id) {
                share.resize(s.body_global.len(), D::V::default());
                D::add_reactions(&s.contacts, &mut share);
            }
            share
        })
        .collect();
    let remote = ranks.map(|r| r.share_reactions(d, &shares, observed));
    let mut out = vec![D::V::default(); slots];
    for (s, sub) in d.subs.iter().enumerate() {
        match &remote {
            Some(rem) if !rem.is_own(s) => {
                // the observed bodies' shares from the subdomain's rank
                for (l, v) in rem.of(s) {
                    add(&mut out[slot(sub.body_global[l])], v);
                }
            }
            _ => {
                for (l, v) in shares[s].iter().enumerate() {
                    add(&mut out[slot(sub.body_global[l])], v.as_ref());
                }
            }
        }
    }
    D::set_reactions(w, out);
}

fn add<V: AsMut<[f64]>>(x: &mut V, y: &[f64]) {
    for (a, b) in x.as_mut().iter_mut().zip(y) {
        *a += b;
    }
}

/// The other ranks' shares of the observed bodies: per subdomain, (local body,
/// values) in local order.
pub(super) struct Remote {
    pub own: Vec<bool>,
    /// Per subdomain: its observed local bodies, and where their values start.
    pub local: Vec<Vec<u32>>,
    pub at: Vec<usize>,
    pub values: Vec<f64>,
    pub ndof: usize,
}

impl Remote {
    fn is_own(&self, s: usize) -> bool {
        self.own[s]
    }
    fn of(&self, s: usize) -> impl Iterator<Item = (usize, &[f64])> + '_ {
        self.local[s].iter().enumerate().map(move |(k, &l)| {
            (
                l as usize,
                &self.values[self.at[s] + k * self.ndof..self.at[s] + (k + 1) * self.ndof],
            )
        })
    }
}

/// Each subdomain's local ids of the observed bodies (ascending local order).
pub(super) fn observed_local<D: Family>(d: &Decomposition<D>, observed: &[u32]) -> Vec<Vec<u32>> {
    d.subs
        .iter()
        .map(|s| {
            (0..s.body_global.len() as u32)
                .filter(|&l| observed.binary_search(&s.body_global[l as usize]).is_ok())
                .collect()
        })
        .collect()
}
