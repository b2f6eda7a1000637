//! The end of a step with bodies stepped per rank (docs/SCALING.md, "Bodies owned
//! per rank", item 2): after the NSCDD iteration a rank needs, of the other ranks'
//! subdomains, only the copy velocities of the bodies it steps (its write-back of
//! those bodies: a body's one copy, or the average of an interface body's copies),
//! not every subdomain's results.
//!
//! ```text
//! requests  (subdomain, local body) of each other rank's subdomain copy whose body
//!           this rank steps: one all-gather of those pairs
//! answers   each rank the velocities of its subdomains' copies any rank asked for,
//!           once each, in (subdomain, body) order: one all-gather of those copies
//! ```
//!
//! Both lists are as long as the rank boundaries (the halos), not the sample; the
//! write-back then reads the own subdomains and the copies received only
//! (`attach::write_back_held`). The
//! other ranks' F_Γ are left as they were: a rank glues and warm-starts only its own
//! subdomains' copies, and before a repartition (when subdomains change ranks) the
//! whole results are shared instead ([`RankState::share_results`]). Every copy a
//! rank writes back is the one its subdomain's rank computed, so the results stay
//! bitwise those of one process.

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
        let mut ask = Vec::new();
        for s in d.subs.iter_mut().filter(|s| self.rank_of[s.id as usize] != me) {
            s.vel.resize(s.body_global.len(), D::V::default());
            for (l, g) in s.body_global.iter().enumerate() {
                if active.is_none_or(|a| a.binary_search(g).is_ok()) {
                    ask.extend([f64::from(s.id), l as f64]);
                }
            }
        }
        let (_, asked) = self.all_gather_any(&ask);
        let mut mine: Vec<(u32, u32)> = asked
            .chunks_exact(2)
            .map(|x| (x[0] as u32, x[1] as u32))
            .filter(|&(s, _)| self.rank_of[s as usize] == me)
            .collect();
        mine.sort_unstable();
        mine.dedup();
        let mut answer = Vec::with_capacity(mine.len() * (2 + ndof));
        for &(s, l) in &mine {
            let sub = &d.subs[s as usize];
            debug_assert_eq!(sub.id, s, "subdomains in id order");
            answer.extend([f64::from(s), f64::from(l)]);
            answer.extend_from_slice(sub.vel[l as usize].as_ref());
        }
        let (_, got) = self.all_gather_any(&answer);
        let mut answered = self.answered.take().unwrap_or_default();
        answered.clear();
        for x in got.chunks_exact(2 + ndof) {
            let (s, l) = (x[0] as usize, x[1] as usize);
            if self.rank_of[s] != me {
                d.subs[s].vel[l].as_mut().copy_from_slice(&x[2..]);
                answered.push((s as u32, l as u32));
            }
        }
        self.answered = Some(answered);
    }
}
