//! NSCDD across processes: the subdomains spread over the ranks of a [`Cluster`].
//!
//! Every rank holds the whole world (replicated data): it computes the free
//! velocities, detects the contacts and splits them over the grid exactly as a
//! one-process run does (the same code on the same data gives the same numbers).
//! Then each rank sweeps and glues only its own subdomains:
//!
//! ```text
//! ranks:   a contiguous run of subdomain ids per rank, balanced by contact count
//!          (ids follow the grid x-first, so a rank's subdomains are neighbors and
//!          few ranks share interface bodies), or a greedy assignment when that is
//!          much better balanced ([`balanced_ranks`]); chosen again at every
//!          repartition
//! repeat {
//!     own subdomains: `sweeps_per_gluing` NLGS sweeps
//!     decentralized: one message to each rank that shares interface bodies with
//!         this one (non-blocking sends and receives), then each own subdomain
//!         glues its copies ([`super::schemes`], unchanged)
//!     centralized:   gather the interface velocities on rank 0, solve every
//!         chain there, scatter each rank its copies' increments
//!     check stages:  every rank's per-subdomain sums and residual shares gathered
//!         on every rank (one all-gather), merged in subdomain order
//! }
//! the converged impulses, copy velocities and F_Γ of every subdomain gathered on
//! every rank (one all-gather), then the write-back and F_Γ store as in one process
//! ```
//!
//! Since every subdomain is swept and glued by the same arithmetic as in one process
//! and every reduction runs in subdomain order, a run gives bitwise the results of
//! the same decomposition run in one process, whatever the number of ranks.
//!
//! Between repartitions, for rigid bodies (and attached families that name the
//! world bodies they touch, [`super::Attached::held_everywhere`]: every rank steps
//! those), each rank holds only its subdomains'
//! contacts ([`super::local`]): it detects and builds those alone, the other ranks'
//! subdomains are shells (the bodies near it, [`super::shells`]), and the end of
//! the step carries only the copy velocities a rank asked for, point to point
//! ([`super::rank_share`]); a repartition merges every rank's bounds and counts
//! and detects again; each rank steps only the bodies near its cells
//! ([`super::owned`]). What is not distributed yet (docs/SCALING.md): the bodies'
//! arrays (every rank allocates the whole sample); with the centralized scheme or
//! while a rank steps every body, the shells' body lists (all-gathered) and, before
//! a repartition, every subdomain's results.

use super::cluster::Cluster;
use super::family::Family;
use super::gluing::GluePartial;
use super::partition::{Decomposition, Interface};
pub use super::rank_balance::{balanced_ranks, contiguous_ranks};
use super::rank_link::{RankLink, RankTransport};
pub use super::rank_totals::totals_json;
use super::schemes::{self, glue_stage, ChainBuffers, GlueBuffers, Scheme};
use super::subdomain::{Subdomain, SubdomainSolver};
use super::transport::TransportStats;
use crate::norms::Sums;
use std::time::Instant;

/// Values per subdomain in a check stage's all-gather: the 8 sums and the 4 fields
/// of the gluing residual share.
const CHECK_VALUES: usize = 12;

/// Totals of one rank over a run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RankTotals {
    pub steps: u64,
    /// Gluing messages and values this rank sent (point to point, or its parts of
    /// the centralized gather/scatter), and the rounds of gluing exchanges.
    pub sent: TransportStats,
    pub rounds: u64,
    /// This rank's parts of the reductions (check stages' and end-of-step
    /// all-gathers, counted as one message to each other rank).
    pub reduce: TransportStats,
    /// Seconds in gluing exchanges, in the check and end-of-step gathers, and in the
    /// whole distributed iteration (sweeps included).
    pub exchange_seconds: f64,
    pub reduce_seconds: f64,
    pub solve_seconds: f64,
    /// Ranks this rank sent gluing messages to, over the run (ascending).
    pub peers: Vec<u32>,
    /// Bodies this rank stepped, summed over the steps ([`super::owned`]), and
    /// bodies' states it sent to other ranks (to those whose halo they entered, to
    /// all before a full step, to rank 0 for the outputs).
    pub bodies_stepped: u64,
    pub bodies_sent: u64,
    /// Bodies this rank's world held in its steps (slots), summed over the steps,
    /// and the most it held in one step.
    pub bodies_held: u64,
    pub bodies_held_max: u64,
    /// The contacts of the restart's state this rank's world held before its first
    /// step kept its own (all of them unless the state was read in part,
    /// [`super::RestartPart`]); 0 without a restart.
    pub restart_contacts: u64,
    /// The bodies this rank's world held before a fresh run's first step: all of
    /// them unless the scene was loaded in part ([`crate::scene::part`]).
    pub loaded_bodies: u64,
    /// Bodies of the other ranks' subdomains (shells) this rank held, summed over
    /// the steps, and the steps whose shells were limited ([`super::shells`]).
    pub shell_bodies: u64,
    pub limited_shells: u64,
    /// The attached families' bodies this rank stepped, and their bodies, summed
    /// over the steps stepped in part ([`super::Attached::solved_on`]).
    pub family_bodies_stepped: u64,
    pub family_bodies: u64,
    /// The attached families' bodies whose data only their stepping ranks need
    /// this rank held, summed over the same steps ([`super::Attached::built_bodies`]).
    pub family_bodies_built: u64,
    /// The attached families' contacts this rank held, summed over the steps
    /// ([`super::Attached::keep_own`]).
    pub family_contacts: u64,
    /// The attached families' contacts their detection found on this rank,
    /// summed over the steps ([`super::Attached::after_free_velocity_own`]).
    pub family_detected: u64,
    /// The attached families' bodies whose boundary this rank held current after
    /// each step stepped in part ([`super::Attached::near_bodies`]).
    pub family_bodies_near: u64,
}

/// The multi-process state of an NSCDD solver.
pub struct RankState {
    pub cluster: Box<dyn Cluster>,
    /// Rank of each subdomain (the last repartition's).
    pub rank_of: Vec<u32>,
    /// On a distributed repartition's step, the ranks of the last step's subdomains.
    pub(super) old_rank_of: Vec<u32>,
    link: RankLink,
    glue: GlueBuffers,
    chain: ChainBuffers,
    pub(super) send: Vec<f64>,
    pub(super) all: Vec<f64>,
    pub(super) counts: Vec<usize>,
    per_sub: Vec<Vec<f64>>,
    per_sub_out: Vec<Vec<f64>>,
    parts: Vec<GluePartial>,
    pub totals: RankTotals,
    /// The step runs with contacts held per rank ([`super::local`]): the other
    /// ranks' subdomains are shells without contacts, their impulses not exchanged.
    pub(super) local: bool,
    /// After a step whose end came by requests ([`RankState::share_requested`]):
    /// the other ranks' copies (subdomain, local body) this rank received, the only
    /// ones of their subdomains up to date here.
    pub(super) answered: Option<Vec<(u32, u32)>>,
    /// The process's CPU seconds and the cluster's waits when the rank's run started
    /// (after loading).
    pub(super) cpu_start: f64,
    pub(super) wait_start: (f64, f64),
}

impl RankState {
    pub fn new(cluster: Box<dyn Cluster>) -> Self {
        let wait_start = cluster.waited();
        RankState {
            cluster,
            rank_of: Vec::new(),
            old_rank_of: Vec::new(),
            link: RankLink::default(),
            glue: GlueBuffers::default(),
            chain: ChainBuffers::default(),
            send: Vec::new(),
            all: Vec::new(),
            counts: Vec::new(),
            per_sub: Vec::new(),
            per_sub_out: Vec::new(),
            parts: Vec::new(),
            totals: RankTotals::default(),
            local: false,
            answered: None,
            cpu_start: super::cluster::cpu_seconds(false),
            wait_start,
        }
    }

    /// The ranks of the `ns` subdomains of a step whose contacts go to `owner`:
    /// chosen again (balanced by contact count) at a repartition, else kept. Returns
    /// which subdomains are this rank's.
    pub fn assign(&mut self, owner: &[u32], ns: usize, repartition: bool) -> Vec<bool> {
        if repartition || self.rank_of.len() != ns {
            self.rank_of = super::rank_balance::ranks_by_owner(owner.iter().copied(), ns, self.cluster.size());
        }
        let me = self.cluster.rank();
        self.rank_of.iter().map(|&r| r == me).collect()
    }

    /// Per-rank counts of `per(subdomain)` values, and where each subdomain's values
    /// start in the gathered buffer (rank order, then subdomain order in a rank).
    pub(super) fn counts_by(&mut self, ns: usize, per: impl Fn(usize) -> usize) -> Vec<usize> {
        self.counts.clear();
        self.counts.resize(self.cluster.size() as usize, 0);
        let mut at = vec![0usize; ns];
        for (s, a) in at.iter_mut().enumerate() {
            let r = self.rank_of[s] as usize;
            *a = self.counts[r];
            self.counts[r] += per(s);
        }
        let mut start = 0;
        let mut displ = vec![0usize; self.counts.len()];
        for (d, &c) in displ.iter_mut().zip(&self.counts) {
            *d = start;
            start += c;
        }
        for (s, a) in at.iter_mut().enumerate() {
            *a += displ[self.rank_of[s] as usize];
        }
        at
    }

    /// `k` values of every subdomain on every rank, by subdomain id: this rank's
    /// subdomains' from `own(s, out)` (which appends them), the others' from their
    /// ranks (one all-gather).
    pub(super) fn per_subdomain(&mut self, ns: usize, k: usize, own: impl FnMut(usize, &mut Vec<f64>)) -> Vec<f64> {
        let (at, all) = self.per_subdomain_v(ns, |_| k, own);
        at.iter().flat_map(|&a| all[a..a + k].iter().copied()).collect()
    }

    /// As [`RankState::per_subdomain`] with `len(s)` values for subdomain s (known
    /// on every rank): where each subdomain's values start, and the values.
    pub(super) fn per_subdomain_v(
        &mut self,
        ns: usize,
        len: impl Fn(usize) -> usize,
        own: impl FnMut(usize, &mut Vec<f64>),
    ) -> (Vec<usize>, Vec<f64>) {
        let at = self.gather_per_subdomain(ns, len, own);
        (at, std::mem::take(&mut self.all))
    }

    /// As [`RankState::per_subdomain_v`], the values left in `self.all` (its buffer
    /// kept: for the reductions of every stage).
    pub(super) fn gather_per_subdomain(
        &mut self,
        ns: usize,
        len: impl Fn(usize) -> usize,
        mut own: impl FnMut(usize, &mut Vec<f64>),
    ) -> Vec<usize> {
        let t0 = Instant::now();
        let me = self.cluster.rank();
        self.send.clear();
        for s in (0..ns).filter(|&s| self.rank_of[s] == me) {
            own(s, &mut self.send);
        }
        let at = self.counts_by(ns, len);
        self.reduced(self.send.len());
        self.cluster.all_gather(&self.send, &self.counts, &mut self.all);
        self.totals.reduce_seconds += t0.elapsed().as_secs_f64();
        at
    }

    /// Records this rank's part of a gluing collective (centralized scheme).
    fn sent(&mut self, messages: u64, values: usize) {
        self.link.stats.messages += messages;
        self.link.stats.values += values as u64;
    }

    /// Records this rank's part of a reduction (check stages, end of step): an
    /// all-gather counted as this rank's values sent to each other rank.
    pub(super) fn reduced(&mut self, values: usize) {
        let others = self.cluster.size() as u64 - 1;
        self.totals.reduce.messages += others;
        self.totals.reduce.values += values as u64 * others;
    }

    /// The centralized gluing across ranks; returns the own subdomains' residual
    /// shares (subdomain order).
    fn central<D: Family>(&mut self, subs: &mut [&mut Subdomain<D>], iface: &Interface, only_fresh: bool, own: &mut Vec<GluePartial>) {
        let (me, np, ns) = (self.cluster.rank(), self.cluster.size(), subs.len());
        let values = |s: &Subdomain<D>| s.iface_off.last().copied().unwrap_or(0) as usize;
        let t0 = Instant::now();
        self.send.clear();
        for s in subs.iter().filter(|s| self.rank_of[s.id as usize] == me) {
            for q in 0..s.slots() {
                s.interface_velocity(q, &mut self.send);
            }
        }
        let at = self.counts_by(ns, |s| values(&*subs[s]));
        if me != 0 {
            self.sent(1, self.send.len());
        }
        self.cluster.gather(&self.send, &self.counts, &mut self.all);
        if me == 0 {
            // unpack per subdomain, solve, pack per rank
            self.per_sub.resize_with(ns, Vec::new);
            self.per_sub_out.resize_with(ns, Vec::new);
            for (s, v) in self.per_sub.iter_mut().enumerate() {
                v.clear();
                let (pos, n) = (at[s], values(&*subs[s]));
                v.extend_from_slice(&self.all[pos..pos + n]);
            }
            self.parts.clear();
            self.parts.resize(ns, GluePartial::default());
            let subs = &*subs;
            schemes::root_solve(
                &self.per_sub,
                &mut self.per_sub_out,
                &mut self.parts,
                iface,
                |s| (&subs[s].iface_ib, &subs[s].iface_k),
                only_fresh,
                &mut self.chain,
            );
            self.all.clear();
            for r in 0..np {
                for s in (0..ns).filter(|&s| self.rank_of[s] == r) {
                    self.all.extend_from_slice(&self.per_sub_out[s]);
                    let p = &self.parts[s];
                    self.all.extend([p.jump2, p.links as f64, p.v2, p.copies as f64]);
                }
            }
        }
        let _ = self.counts_by(ns, |s| values(&*subs[s]) + 4);
        if me == 0 {
            // the root's scatter: everything but its own part
            self.sent(np as u64 - 1, self.all.len() - self.counts[0]);
        }
        let mut mine = std::mem::take(&mut self.send);
        self.cluster.scatter(&self.all, &self.counts, &mut mine);
        self.link.rounds += 1;
        self.link.seconds += t0.elapsed().as_secs_f64();
        let mut pos = 0;
        own.clear();
        for s in subs.iter_mut().filter(|s| self.rank_of[s.id as usize] == me) {
            for q in 0..s.slots() {
                let n = (s.iface_off[q + 1] - s.iface_off[q]) as usize;
                if !only_fresh || iface.fresh[s.iface_ib[q] as usize] {
                    s.glue(q, &mine[pos..pos + n]);
                }
                pos += n;
            }
            let p = &mine[pos..pos + 4];
            own.push(GluePartial {
                jump2: p[0],
                links: p[1] as u64,
                v2: p[2],
                copies: p[3] as u64,
            });
            pos += 4;
        }
        self.send = mine;
    }

    /// One gluing stage over the own subdomains; their residual shares in `own`.
    fn glue<D: Family>(
        &mut self,
        subs: &mut [&mut Subdomain<D>],
        iface: &Interface,
        scheme: Scheme,
        only_fresh: bool,
        own: &mut Vec<GluePartial>,
    ) {
        match scheme {
            Scheme::Centralized => self.central(subs, iface, only_fresh, own),
            Scheme::Decentralized => {
                let me = self.cluster.rank();
                let rank_of = &self.rank_of;
                let mut subs: Vec<&mut Subdomain<D>> = subs.iter_mut().filter(|s| rank_of[s.id as usize] == me).map(|s| &mut **s).collect();
                let mut t = RankTransport {
                    link: &mut self.link,
                    cl: &mut *self.cluster,
                };
                *own = glue_stage(&mut subs, iface, Scheme::Decentralized, &mut t, only_fresh, &mut self.glue);
            }
        }
    }

    /// A check stage: every subdomain's sums and residual share, on every rank, merged
    /// in subdomain order.
    fn check<D: Family>(&mut self, subs: &[&mut Subdomain<D>], own: &[GluePartial]) -> (Sums, GluePartial) {
        let me = self.cluster.rank();
        let t0 = Instant::now();
        self.send.clear();
        let mut parts = own.iter();
        for s in subs.iter().filter(|s| self.rank_of[s.id as usize] == me) {
            let u = &s.sums;
            let p = parts.next().copied().unwrap_or_default();
            self.send.extend([
                u.sum_dvdv,
                u.sum_wrwr,
                u.sum_wrr,
                u.sum_dvdvrr,
                u.sum_dvor,
                u.max_dvdv,
                u.max_dvdvrr,
                u.nactif as f64,
                p.jump2,
                p.links as f64,
                p.v2,
                p.copies as f64,
            ]);
        }
        let at = self.counts_by(subs.len(), |_| CHECK_VALUES);
        self.reduced(self.send.len());
        self.cluster.all_gather(&self.send, &self.counts, &mut self.all);
        self.totals.reduce_seconds += t0.elapsed().as_secs_f64();
        let (mut sums, mut g) = (Sums::default(), GluePartial::default());
        // merged in subdomain order
        for &a in &at {
            let x = &self.all[a..a + CHECK_VALUES];
            sums.merge(&Sums {
                sum_dvdv: x[0],
                sum_wrwr: x[1],
                sum_wrr: x[2],
                sum_dvdvrr: x[3],
                sum_dvor: x[4],
                max_dvdv: x[5],
                max_dvdvrr: x[6],
                nactif: x[7] as u64,
            });
            g.merge(&GluePartial {
                jump2: x[8],
                links: x[9] as u64,
                v2: x[10],
                copies: x[11] as u64,
            });
        }
        (sums, g)
    }

    /// Every subdomain's impulses, copy velocities and F_Γ from its rank to all; with
    /// `requests` (contacts held per rank, no repartition next or limited shells,
    /// [`super::shells`]), only the copy velocities of the bodies this rank steps
    /// (`Some(None)`: all of them; [`RankState::share_requested`], which also
    /// all-gathers the attached families' packed parts).
    fn share_results<D: Family>(&mut self, d: &mut Decomposition<D>, requests: Option<Option<&[u32]>>) {
        if let (Some(active), true) = (requests, self.local) {
            return self.share_requested(d, active);
        }
        self.answered = None;
        let ndof = super::subdomain::dofs::<D>();
        let me = self.cluster.rank();
        let t0 = Instant::now();
        // copies of other ranks' subdomains were not given starting velocities; the
        // attached families' parts travel as their packed results, after the rigid values
        let parts_len = |s: &Subdomain<D>| s.parts.0.iter().map(|(_, p)| p.packed_len()).sum::<usize>();
        let with_r = !self.local;
        let r_len = |s: &Subdomain<D>| if with_r { D::len(&s.contacts) * D::SPACE } else { 0 };
        let size = |s: &Subdomain<D>| r_len(s) + (s.body_global.len() + s.f_gamma.len()) * ndof + parts_len(s);
        self.send.clear();
        for s in d.subs.iter().filter(|s| self.rank_of[s.id as usize] == me) {
            for a in (0..D::len(&s.contacts)).filter(|_| with_r) {
                self.send.extend_from_slice(D::r(&s.contacts, a));
            }
            for v in s.vel.iter().chain(&s.f_gamma) {
                self.send.extend_from_slice(v.as_ref());
            }
            for (_, p) in &s.parts.0 {
                p.pack(&mut self.send);
            }
        }
        let at = self.counts_by(d.subs.len(), |k| size(&d.subs[k]));
        self.reduced(self.send.len());
        self.cluster.all_gather(&self.send, &self.counts, &mut self.all);
        for s in d.subs.iter_mut() {
            if self.rank_of[s.id as usize] == me {
                continue;
            }
            let mut pos = at[s.id as usize];
            for a in 0..D::len(&s.contacts) {
                D::r_mut(&mut s.contacts, a).copy_from_slice(&self.all[pos..pos + D::SPACE]);
                pos += D::SPACE;
            }
            s.vel.resize(s.body_global.len(), D::V::default());
            for v in s.vel.iter_mut().chain(s.f_gamma.iter_mut()) {
                v.as_mut().copy_from_slice(&self.all[pos..pos + ndof]);
                pos += ndof;
            }
            for (_, p) in s.parts.0.iter_mut() {
                let n = p.packed_len();
                p.unpack(&self.all[pos..pos + n]);
                pos += n;
            }
        }
        self.totals.reduce_seconds += t0.elapsed().as_secs_f64();
    }
}

/// The NSCDD iteration of one step over the ranks (see the module docs): at most
/// `max_stages` stages of `per` sweeps (relaxation `omega`) and one gluing, a check
/// every `k` stages and at the last, `converged(sums, residual share)` deciding on
/// every rank from the same merged numbers; then every subdomain's results on every
/// rank, or with `requests` the copies this rank asked for. The subdomains' ranks
/// are those of [`RankState::assign`] at the partition; `fresh`: whether any
/// interface body is fresh (the same on every rank: the ranks glue those together
/// first). Returns the stages run and this step's exchange counts.
#[allow(clippy::too_many_arguments)]
pub(super) fn iterate<D: Family>(
    st: &mut RankState,
    d: &mut Decomposition<D>,
    scheme: Scheme,
    (per, omega, max_stages, k): (u32, f64, u32, u32),
    (threads, workers): (usize, &mut super::team::Workers),
    (mut mixer, requests, fresh): (Option<&mut super::anderson::StageMixer>, Option<Option<&[u32]>>, bool),
    mut converged: impl FnMut(&Sums, &GluePartial) -> bool,
) -> (u32, TransportStats) {
    let t0 = Instant::now();
    let me = st.cluster.rank();
    assert_eq!(st.rank_of.len(), d.subs.len(), "subdomains assigned to ranks at the partition");
    st.link.setup(&d.subs, &st.rank_of, me);
    st.link.stats = TransportStats::default();
    st.link.seconds = 0.0;
    let mut own = Vec::new();
    // the rank's subdomains swept by a team of `threads` (hybrid: threads inside
    // the rank; each subdomain on its own data, so any thread count gives the same
    // result), glued and checked over the ranks on this thread
    let rank_of = st.rank_of.clone();
    let mine = |k: usize| rank_of[k] == me;
    let iface = &d.iface;
    let mine_id = |id: u32| rank_of[id as usize] == me;
    let (stages, _) = super::team::with_team(&mut d.subs, (threads, &mine), iface, workers, |team| {
        if fresh {
            team.with_all(|subs| st.glue(subs, iface, scheme, true, &mut own));
        }
        if let Some(m) = mixer.as_deref_mut() {
            team.with_all(|subs| m.start(subs, &mine_id));
        }
        let (stages, ok) = crate::solver::check_loop(max_stages, k, |check| {
            team.sweep(per, omega, check);
            team.with_all(|subs| {
                own.clear();
                // (a rank-local test: with limited shells a rank's interface holds
                // the bodies near it only; the decentralized scheme then talks to
                // the peers sharing those alone, and limited shells are never used
                // with the centralized one, whose gather is collective)
                if !iface.is_empty() {
                    st.glue(subs, iface, scheme, false, &mut own);
                }
                let done = check && {
                    let (sums, g) = st.check(subs, &own);
                    converged(&sums, &g)
                };
                if let (Some(m), false) = (mixer.as_deref_mut(), done) {
                    let ns = subs.len();
                    m.after(subs, &mine_id, &mut Reduced { st: &mut *st, ns });
                }
                done
            })
        });
        if let (Some(m), false) = (mixer, ok) {
            team.with_all(|subs| m.give_up(subs, &mine_id));
        }
        (stages, ok)
    });
    st.share_results(d, requests);
    let t = &mut st.totals;
    t.steps += 1;
    t.sent.messages += st.link.stats.messages;
    t.sent.values += st.link.stats.values;
    t.rounds += st.link.rounds;
    st.link.rounds_step = st.link.rounds;
    st.link.rounds = 0;
    t.exchange_seconds += st.link.seconds;
    t.solve_seconds += t0.elapsed().as_secs_f64();
    let peers: Vec<u32> = match scheme {
        _ if st.link.rounds_step == 0 => Vec::new(),
        Scheme::Decentralized => st.link.peers.clone(),
        Scheme::Centralized if me == 0 => (1..st.cluster.size()).collect(),
        Scheme::Centralized => vec![0],
    };
    for p in peers {
        if let Err(i) = t.peers.binary_search(&p) {
            t.peers.insert(i, p);
        }
    }
    (stages, st.link.stats)
}

/// The dot products of Anderson's mixing over the ranks: every subdomain's values
/// gathered on every rank, summed in subdomain order.
struct Reduced<'a> {
    st: &'a mut RankState,
    ns: usize,
}

impl crate::solver::anderson::Reduce for Reduced<'_> {
    fn reduce(&mut self, local: &[f64], k: usize, out: &mut [f64]) {
        if k == 0 {
            return;
        }
        // `local`: this rank's subdomains' k values each, in subdomain order
        let mut own = local.chunks_exact(k);
        let at = self
            .st
            .gather_per_subdomain(self.ns, |_| k, |_, v| v.extend_from_slice(own.next().unwrap_or_default()));
        let all = &self.st.all;
        crate::solver::anderson::sum_in_order(at.iter().map(|&a| &all[a..a + k]), k, out);
    }
}
