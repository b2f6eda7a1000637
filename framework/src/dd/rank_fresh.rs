//! The starting F_Γ of a body whose copies changed, on ranks with contacts held per
//! rank (on a repartition step from the store routed there, [`super::shells`]).
//!
//! A body whose set of copies changed since the last step is *fresh*: its copies
//! start from their kept F_Γ (zero for a new copy) with the mean removed
//! ([`super::partition::zero_mean`]). Between repartitions a rank keeps only its
//! own subdomains' F_Γ up to date (`rank_share`: the other ranks' are not sent), so
//! the mean over copies held by several ranks needs the others' kept values: each
//! rank asks, for the fresh bodies with a copy in its subdomains, the kept F_Γ of
//! their copies in other ranks' subdomains (zero where a copy kept none), and each
//! subdomain's rank answers from its own store (point to point,
//! [`RankState::ask_ranks`]: as long as the fresh bodies at rank boundaries; the
//! asking rank's store may not know those copies, [`super::shells`]). Then every
//! rank starts its copies where one process does, bit for bit.

use super::family::Family;
use super::partition::{zero_mean, Decomposition, FGammaStore};
use super::ranks::RankState;

impl RankState {
    /// Sets the starting F_Γ of this rank's copies of the fresh interface bodies
    /// from every copy's kept F_Γ, asked of its subdomain's rank (module docs); the
    /// caller then makes the own subdomains' starting velocities (once: a family's
    /// part moves its own copies in its warm start). Collective.
    pub(super) fn fresh_f_gamma<D: Family>(&mut self, d: &mut Decomposition<D>, store: &FGammaStore<D::V>) {
        let iface = &d.iface;
        let mut bodies = Vec::new();
        // (subdomain, body) of the other ranks' copies asked: each one's kept F_Γ,
        // zero if it has none (this rank's store may not know: with limited shells
        // it holds the others' copies of the bodies near it only)
        let mut asks = Vec::new();
        for ib in 0..iface.n_rigid {
            let ks = iface.copies(ib);
            if !iface.fresh[ib] || !ks.clone().any(|k| self.is_own(iface.sub[k])) {
                continue;
            }
            bodies.push(ib);
            let g = iface.body[ib];
            asks.extend(ks.map(|k| iface.sub[k]).filter(|&s| !self.is_own(s)).map(|s| (s, g)));
        }
        let ndof = super::subdomain::dofs::<D>();
        let got = self.ask_ranks(&asks, ndof, |s, g, out| {
            out.extend_from_slice(store.get(g, s).unwrap_or_default().as_ref())
        });
        // the answers in the order asked: the loop below meets the same copies in
        // the same order
        let mut answers = got.chunks_exact(ndof);
        let iface = &d.iface;
        for ib in bodies {
            let g = iface.body[ib];
            let mut f: Vec<D::V> = iface
                .copies(ib)
                .map(|k| {
                    let s = iface.sub[k];
                    if self.is_own(s) {
                        return store.get(g, s).unwrap_or_default();
                    }
                    let mut v = D::V::default();
                    if let Some(x) = answers.next() {
                        v.as_mut().copy_from_slice(x);
                    }
                    v
                })
                .collect();
            zero_mean(&mut f);
            for (j, k) in iface.copies(ib).enumerate() {
                let s = iface.sub[k];
                if self.is_own(s) {
                    d.subs[s as usize].f_gamma[iface.slot[k] as usize] = f[j];
                }
            }
        }
    }
}
