//! The end of a step with bodies stepped per rank (docs/SCALING.md, "Bodies owned
//! per rank", item 2): after the NSCDD iteration a rank needs, of the other ranks'
//! subdomains, only the copy velocities of the bodies it steps (its write-back of
//! those bodies: a body's one copy, or the average of an interface body's copies),
//! not every subdomain's results.
//!
//! ```text
//! counts    how many copies this rank asks of each other rank: one all-to-all of
//!           one value per pair of ranks
//! requests  (subdomain, local body) of each other rank's subdomain copy whose body
//!           this rank steps, sent to that subdomain's rank (point to point, with
//!           the ranks that ask of this one or are asked by it)
//! answers   each asking rank the velocities of the copies it asked for, in its
//!           order (point to point, the same peers)
//! ```
//!
//! The messages are as long as the rank boundaries (the halos), and go to the
//! neighbouring ranks only (an all-gather of the pairs, then of the answers, sent
//! each rank every other rank's boundary before 2026-11-25); the write-back then
//! reads the own subdomains and the copies received only
//! (`attach::write_back_held`). The
//! other ranks' F_Γ are left as they were: a rank glues and warm-starts only its own
//! subdomains' copies, and before a repartition (when subdomains change ranks) the
//! whole results are shared instead ([`RankState::share_results`]). Every copy a
//! rank writes back is the one its subdomain's rank computed, so the results stay
//! bitwise those of one process.

use super::family::Family;
use super::partition::Decomposition;
use super::ranks::RankState;
use std::time::Instant;

impl RankState {
    /// The copy velocities that the bodies `active` (this rank's, ascending; `None`:
    /// every body) have in other ranks' subdomains, from those ranks, into the
    /// shells (module docs). Collective.
    pub(super) fn share_requested<D: Family>(&mut self, d: &mut Decomposition<D>, active: Option<&[u32]>) {
        let t0 = Instant::now();
        let ndof = super::subdomain::dofs::<D>();
        let (me, np) = (self.cluster.rank(), self.cluster.size() as usize);
        // the pairs this rank asks of each rank, in subdomain then body order
        let mut ask: Vec<Vec<(u32, u32)>> = vec![Vec::new(); np];
        for s in d.subs.iter_mut().filter(|s| self.rank_of[s.id as usize] != me) {
            s.vel.resize(s.body_global.len(), D::V::default());
            let r = self.rank_of[s.id as usize] as usize;
            for (l, g) in s.body_global.iter().enumerate() {
                if active.is_none_or(|a| a.binary_search(g).is_ok()) {
                    ask[r].push((s.id, l as u32));
                }
            }
        }
        let to: Vec<u64> = ask.iter().map(|a| a.len() as u64).collect();
        let mut from = Vec::new();
        self.cluster.all_to_all(&to, &mut from);
        self.sent_share(np - 1, np - 1);
        // peers: the ranks asked by this one or asking of it (a symmetric relation)
        let peers: Vec<u32> = (0..np as u32)
            .filter(|&r| r != me && (to[r as usize] > 0 || from[r as usize] > 0))
            .collect();
        let out: Vec<Vec<f64>> = peers
            .iter()
            .map(|&r| ask[r as usize].iter().flat_map(|&(s, l)| [f64::from(s), f64::from(l)]).collect())
            .collect();
        let mut inbox = vec![Vec::new(); peers.len()];
        self.cluster.exchange(&peers, &out, &mut inbox);
        self.sent_share(out.iter().filter(|o| !o.is_empty()).count(), out.iter().map(Vec::len).sum());
        // the answers: the copies each peer asked for, in its order
        let out: Vec<Vec<f64>> = inbox
            .iter()
            .map(|q| {
                let mut a = Vec::with_capacity(q.len() / 2 * ndof);
                for x in q.chunks_exact(2) {
                    let sub = &d.subs[x[0] as usize];
                    debug_assert_eq!(self.rank_of[sub.id as usize], me, "asked of its rank");
                    a.extend_from_slice(sub.vel[x[1] as usize].as_ref());
                }
                a
            })
            .collect();
        self.cluster.exchange(&peers, &out, &mut inbox);
        self.sent_share(out.iter().filter(|o| !o.is_empty()).count(), out.iter().map(Vec::len).sum());
        let mut answered = self.answered.take().unwrap_or_default();
        answered.clear();
        for (&r, got) in peers.iter().zip(&inbox) {
            for (&(s, l), v) in ask[r as usize].iter().zip(got.chunks_exact(ndof)) {
                d.subs[s as usize].vel[l as usize].as_mut().copy_from_slice(v);
                answered.push((s, l));
            }
        }
        self.answered = Some(answered);
        self.totals.reduce_seconds += t0.elapsed().as_secs_f64();
    }

    /// Records messages and values this rank sent at the end of a step.
    fn sent_share(&mut self, messages: usize, values: usize) {
        self.totals.reduce.messages += messages as u64;
        self.totals.reduce.values += values as u64;
    }
}
