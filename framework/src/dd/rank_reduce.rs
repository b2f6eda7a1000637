//! The reductions of [`RankState`] that outputs and contacts held per rank need:
//! values per subdomain from the subdomains' ranks, and gathers of any length.

use super::family::Family;
use super::partition::Decomposition;
use super::ranks::RankState;
use std::time::Instant;

impl RankState {
    /// Every rank's `mine` (any lengths) concatenated in rank order, and the lengths
    /// (two all-gathers).
    pub(super) fn all_gather_any(&mut self, mine: &[f64]) -> (Vec<usize>, Vec<f64>) {
        let t0 = Instant::now();
        let counts = self.lengths(mine.len());
        let mut all = Vec::new();
        self.cluster.all_gather(mine, &counts, &mut all);
        self.reduced(mine.len() + 1);
        self.totals.reduce_seconds += t0.elapsed().as_secs_f64();
        (counts, all)
    }

    /// Every rank's `mine` (the same length on every rank) added element by element,
    /// ranks in order (counts as f64: exact).
    pub(super) fn all_sum(&mut self, mine: &[f64]) -> Vec<f64> {
        let (_, all) = self.all_gather_any(mine);
        let mut sum = vec![0.0; mine.len()];
        for x in all.chunks_exact(mine.len().max(1)) {
            for (t, v) in sum.iter_mut().zip(x) {
                *t += v;
            }
        }
        sum
    }

    /// As [`RankState::all_gather_any`], into rank 0 only (empty elsewhere).
    pub(super) fn gather_any_on_root(&mut self, mine: &[f64]) -> Vec<f64> {
        let counts = self.lengths(mine.len());
        let mut all = Vec::new();
        self.cluster.gather(mine, &counts, &mut all);
        all
    }

    /// Every rank's length `n` (one all-gather).
    fn lengths(&mut self, n: usize) -> Vec<usize> {
        let mut lens = Vec::new();
        self.cluster
            .all_gather(&[n as f64], &vec![1; self.cluster.size() as usize], &mut lens);
        lens.iter().map(|&x| x as usize).collect()
    }

    /// Whether subdomain `s` is this rank's (the last repartition's ranks).
    pub(super) fn is_own(&self, s: u32) -> bool {
        self.rank_of.get(s as usize) == Some(&self.cluster.rank())
    }

    /// The observed bodies' reaction shares of every subdomain, from its rank (one
    /// all-gather; `shares`: this rank's subdomains' shares by local body).
    pub(super) fn share_reactions<D: Family>(
        &mut self,
        d: &Decomposition<D>,
        shares: &[Vec<D::V>],
        observed: &[u32],
    ) -> super::reactions::Remote {
        let ndof = super::subdomain::dofs::<D>();
        let local = super::reactions::observed_local(d, observed);
        let me = self.cluster.rank();
        let (at, values) = self.per_subdomain_v(
            d.subs.len(),
            |s| local[s].len() * ndof,
            |s, out| local[s].iter().for_each(|&l| out.extend_from_slice(shares[s][l as usize].as_ref())),
        );
        super::reactions::Remote {
            own: self.rank_of.iter().map(|&r| r == me).collect(),
            local,
            at,
            values,
            ndof,
        }
    }
}

/// [`RankState::per_subdomain`] on ranks; in one process every subdomain's `k`
/// values from `own`, in subdomain order.
pub(super) fn per_subdomain(ranks: Option<&mut RankState>, ns: usize, k: usize, mut own: impl FnMut(usize, &mut Vec<f64>)) -> Vec<f64> {
    match ranks {
        Some(r) => r.per_subdomain(ns, k, own),
        None => {
            let mut v = Vec::with_capacity(k * ns);
            (0..ns).for_each(|s| own(s, &mut v));
            v
        }
    }
}
