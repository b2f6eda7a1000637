//! The end of a step with bodies stepped per rank (docs/SCALING.md, "Bodies owned
//! per rank", item 2): after the NSCDD iteration a rank needs, of the other ranks'
//! subdomains, only the copy velocities of the bodies it steps (its write-back of
//! those bodies: a body's one copy, or the average of an interface body's copies),
//! not every subdomain's results.
//!
//! The copies go point to point, from each subdomain's rank to the ranks that ask
//! ([`RankState::ask_ranks`]): the messages are as long as the rank boundaries (the
//! halos), and go to the neighbouring ranks only (two all-gathers before
//! 2026-11-25 sent every rank every other rank's boundary); the write-back then
//! reads the own subdomains and the copies received only
//! (`attach::write_back_held`). The other ranks' F_Γ are left as they were: a rank
//! glues and warm-starts only its own subdomains' copies; before a repartition
//! (when subdomains change ranks) the repartition step routes the kept F_Γ
//! ([`super::shells`]), or, with whole shells, the whole results are shared instead
//! ([`RankState::share_results`]). Every copy a rank writes back is the one its
//! subdomain's rank computed, so the results stay bitwise those of one process.

use super::family::Family;
use super::partition::Decomposition;
use super::ranks::RankState;

impl RankState {
    /// The copy velocities that the bodies `active` (this rank's, ascending; `None`:
    /// every body) have in other ranks' subdomains, from those ranks, into the
    /// shells (module docs). Collective.
    pub(super) fn share_requested<D: Family>(&mut self, d: &mut Decomposition<D>, active: Option<&[u32]>) {
        let ndof = super::subdomain::dofs::<D>();
        let me = self.cluster.rank();
        // (subdomain, local body) of the copies asked, in subdomain then body order:
        // their ids on the subdomain's rank, and here (a limited shell's own)
        let (mut asks, mut here) = (Vec::new(), Vec::new());
        for s in d.subs.iter_mut().filter(|s| self.rank_of[s.id as usize] != me) {
            s.vel.resize(s.body_global.len(), D::V::default());
            for (l, g) in s.body_global.iter().enumerate() {
                // (a copy no route named: none, `RankState::route_family_copies`)
                if active.is_none_or(|a| a.binary_search(g).is_ok()) && s.remote_id(l as u32) != u32::MAX {
                    asks.push((s.id, s.remote_id(l as u32)));
                    here.push((s.id, l as u32));
                }
            }
        }
        let subs = &d.subs;
        let got = self.ask_ranks(&asks, ndof, |s, l, out| {
            out.extend_from_slice(subs[s as usize].vel[l as usize].as_ref())
        });
        let mut answered = self.answered.take().unwrap_or_default();
        answered.clear();
        for (&(s, l), v) in here.iter().zip(got.chunks_exact(ndof)) {
            d.subs[s as usize].vel[l as usize].as_mut().copy_from_slice(v);
            answered.push((s, l));
        }
        self.answered = Some(answered);
        self.share_parts(d);
    }

    /// The attached families' parts of the other ranks' subdomains: their packed
    /// results ([`super::LocalPart::pack`]) from each subdomain's rank to every rank
    /// (one all-gather): a family, held whole on every rank, writes back every part.
    /// Nothing without parts or packed values (the same on every rank: they hold
    /// the same families).
    /// Collective.
    fn share_parts<D: Family>(&mut self, d: &mut Decomposition<D>) {
        let len = |s: &super::Subdomain<D>| s.parts.0.iter().map(|(_, p)| p.packed_len()).sum::<usize>();
        // (every rank sees every subdomain's lengths the same, as the all-gather's
        // counts need: none of them, no round)
        if d.subs.iter().all(|s| len(s) == 0) {
            return;
        }
        let me = self.cluster.rank();
        self.send.clear();
        for s in d.subs.iter().filter(|s| self.rank_of[s.id as usize] == me) {
            for (_, p) in &s.parts.0 {
                p.pack(&mut self.send);
            }
        }
        let at = self.counts_by(d.subs.len(), |k| len(&d.subs[k]));
        self.reduced(self.send.len());
        self.cluster.all_gather(&self.send, &self.counts, &mut self.all);
        for s in d.subs.iter_mut().filter(|s| self.rank_of[s.id as usize] != me) {
            let mut pos = at[s.id as usize];
            for (_, p) in s.parts.0.iter_mut() {
                let n = p.packed_len();
                p.unpack(&self.all[pos..pos + n]);
                pos += n;
            }
        }
    }
}
