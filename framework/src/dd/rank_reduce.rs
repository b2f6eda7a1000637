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
        let p = self.cluster.size() as usize;
        let mut lens = Vec::new();
        self.cluster.all_gather(&[mine.len() as f64], &vec![1; p], &mut lens);
        let counts: Vec<usize> = lens.iter().map(|&x| x as usize).collect();
        let mut all = Vec::new();
        self.cluster.all_gather(mine, &counts, &mut all);
        self.reduced(mine.len() + 1);
        self.totals.reduce_seconds += t0.elapsed().as_secs_f64();
        (counts, all)
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
        let t0 = Instant::now();
        let ndof = super::subdomain::dofs::<D>();
        let local = super::reactions::observed_local(d, observed);
        let me = self.cluster.rank();
        self.send.clear();
        for (s, ls) in local.iter().enumerate().filter(|(s, _)| self.rank_of[*s] == me) {
            for &l in ls {
                self.send.extend_from_slice(shares[s][l as usize].as_ref());
            }
        }
        let at = self.counts_by(d.subs.len(), |s| local[s].len() * ndof);
        self.reduced(self.send.len());
        self.cluster.all_gather(&self.send, &self.counts, &mut self.all);
        self.totals.reduce_seconds += t0.elapsed().as_secs_f64();
        super::reactions::Remote {
            own: self.rank_of.iter().map(|&r| r == me).collect(),
            local,
            at,
            values: std::mem::take(&mut self.all),
            ndof,
        }
    }
}
