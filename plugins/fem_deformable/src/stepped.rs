//! The deformable bodies one MPI rank steps (docs/SCALING.md, "Deformable bodies
//! stepped per rank"). On an NSCDD step the family builds its contact list before
//! the partition without any solve ([`Stepped::hold`]: no body stepped yet); after
//! it the framework tells the family which rank solves each contact
//! ([`nscdd::dd::SolvedOn`]), and one rank, the one solving most of a body's
//! contacts (from every rank's counts, [`Stepped::decide`]), steps the body:
//! computes its V_free, its columns of M̂⁻¹ and G at its contact nodes, and its
//! V⁺. Another rank solving some of its contacts asks it for the nodes these
//! touch and receives the body's contact nodes, the free velocity there and
//! those rows of G from it, point to point, for its W_αα, u_free and parts
//! ([`crate::solved`]). A body without contact is stepped
//! by the rank that checked it at load ([`crate::scene::checked_by`]). Every rank
//! still detects every contact (the family's contacts, kept and sorted by
//! detection: their points are the partition's), but builds only the contacts
//! it solves ([`crate::solved::Solved`]),
//! and only the parts of its own subdomains; another rank's subdomain gets a
//! shell part made from its rank's description ([`crate::shells`]). After the
//! write-back, the rank stepping a body gets the impulses of its contacts solved
//! elsewhere ([`crate::impulses`]), computes V⁺ and sends it at the body's
//! boundary to the ranks whose cells it is near ([`crate::near`]), and the
//! body's energies after the step to rank 0 (the history's columns, each body's
//! computed once); the body's whole state stays with it ([`crate::whole`]). Each rank's residual reads only the contacts it solved (the
//! family's sums per subdomain, [`nscdd::dd::Attached::residual_parts_in`]). A
//! body not stepped here builds no G (its contacts' W_αα and parts are never used
//! here), and once it has gone [`RELEASE_AFTER`] steps unstepped here its columns
//! of M̂⁻¹ and its G are dropped, with the factors of its M̂ if it is large
//! ([`RELEASE_MIN_BYTES`]), and after [`RELEASE_MATRICES_AFTER`] a large body's
//! M and K, or a smaller body's if it is far from the rank's cells
//! ([`crate::near`]) (memory per rank; stepped again, it assembles, factors and
//! solves them anew, the same numbers). Loaded on ranks, a rank holds the
//! matrices of the bodies it checked at load only ([`crate::scene::bodies_from`]):
//! the factors of a large one it does not step at the first step are dropped
//! then (its M and K [`RELEASE_MATRICES_AFTER`] − [`RELEASE_AFTER`] steps later),
//! and a body it steps without them is assembled and factored there
//! ([`crate::stage2::free_velocities`]).

use crate::body::FeBody;
use crate::nodes::NodeSet;
use nscdd::dd::SolvedOn;

/// Steps a body goes unstepped on a rank before the rank drops its factors of M̂,
/// its columns of M̂⁻¹ and its G (a body stepped on alternate steps keeps them).
pub const RELEASE_AFTER: u32 = 10;

/// Steps a body goes unstepped on a rank before the rank drops its M and K too
/// (assembling them again costs a scikit-fem assembly: a body whose contacts
/// move between ranks at repartitions keeps them).
pub const RELEASE_MATRICES_AFTER: u32 = 100;

/// The size of a body's M, K and factors ([`crate::scene::matrices_bytes`]'s
/// estimate) from which a rank drops them when it does not step the body: a
/// smaller body keeps them once made (only its columns and G are dropped) unless
/// it is also far from the rank's cells ([`crate::near`]) after
/// [`RELEASE_MATRICES_AFTER`] steps, since making them again costs more time
/// than they hold memory (docs/SCALING.md,
/// "M̂'s factors, M and K held where a body is stepped": 2D bodies of fewer than
/// about 13 000 nodes, 3D bodies of fewer than about 1 200).
pub const RELEASE_MIN_BYTES: f64 = 16.0 * 1024.0 * 1024.0;

/// When a rank drops what it does not step: ([`RELEASE_MIN_BYTES`],
/// [`RELEASE_AFTER`], [`RELEASE_MATRICES_AFTER`]), or the three numbers of
/// `NSCDD_FE_RELEASE` (tests: every body dropped soon, e.g. `"0 2 5"`); results
/// never depend on them.
pub fn release_rule() -> (f64, u32, u32) {
    static RULE: std::sync::OnceLock<(f64, u32, u32)> = std::sync::OnceLock::new();
    *RULE.get_or_init(|| {
        let given = std::env::var("NSCDD_FE_RELEASE").ok().and_then(|v| {
            let x: Vec<f64> = v.split_whitespace().filter_map(|x| x.parse().ok()).collect();
            match x[..] {
                [b, a, m] if b >= 0.0 && a >= 1.0 && m > a => Some((b, a as u32, m as u32)),
                _ => None,
            }
        });
        given.unwrap_or((RELEASE_MIN_BYTES, RELEASE_AFTER, RELEASE_MATRICES_AFTER))
    })
}

/// Which bodies this rank steps in the step in progress (module docs).
#[derive(Default)]
pub struct Stepped {
    /// Stepped in part: (this rank, ranks); `mine` is then the mask.
    on: Option<(u32, u32)>,
    /// Before the partition of an NSCDD step: no body stepped yet.
    held: bool,
    /// Per body, in part: whether this rank steps it (the sender: the rank solving
    /// most of its contacts; without contact, the rank that checked it).
    mine: Vec<bool>,
    /// Per body, in part: whether this rank solves one of its contacts, and
    /// whether another rank does too.
    touched: Vec<bool>,
    shared: Vec<bool>,
    /// In part: (body, rank solving one of its contacts) of the bodies whose
    /// contacts several ranks solve, ascending, once each.
    solvers: Vec<(u32, u32)>,
    /// Per body, in part: the rank stepping it, whose V⁺ the ranks near it take.
    sender: Vec<u32>,
    /// Per body, the last step's `sender` (empty: the state is whole on every
    /// rank, as after a load).
    prev: Vec<u32>,
    /// (h, θ) of the step in progress, in part.
    ht: (f64, f64),
    /// Per body, after the exchange of a step stepped in part: its energies after
    /// the step ([`FeBody::energies`] at u⁺, V⁺), as its sender computed them.
    energy: Vec<[f64; 3]>,
    energy_known: bool,
    /// Per body, in part: the steps since this rank last stepped it (a body not
    /// stepped here since the load counts RELEASE_AFTER − 1 at the first step;
    /// [`release_rule`]).
    idle: Vec<u32>,
    /// The bodies that have just reached [`RELEASE_AFTER`] idle steps, and whether
    /// they have reached [`RELEASE_MATRICES_AFTER`].
    release: Vec<(u32, bool)>,
    /// Per contact (the family's list), in part: whether this rank solves it, and
    /// the rank that does.
    solved: Vec<bool>,
    rank: Vec<u32>,
    /// A failure in the step in progress on this rank ([`Self::fail`]).
    failed: bool,
    /// Which ranks hold each body's boundary current ([`crate::near`]).
    pub near: crate::near::Near,
    /// A body another rank stepped with a non-finite value in the step in
    /// progress (its V⁺ came here with it, [`crate::near::share`]): the step's end
    /// reports a divergence on every rank.
    pub diverged: Option<u32>,
    /// The family's contacts over the ranks, after the exchange of a step
    /// stepped in part ([`crate::impulses::finish`]).
    total: Option<usize>,
}

impl Stepped {
    /// Before the partition: the contact list is built without any body stepped
    /// (no solve), until [`Self::decide`].
    pub fn hold(&mut self, n: usize) {
        self.on = None;
        self.diverged = None;
        self.held = true;
        self.failed = false;
        self.total = None;
        self.energy_known = false;
        self.mine.clear();
        self.mine.resize(n, false);
    }

    /// After the partition ([`nscdd::dd::Attached::solved_on`]; `None`: every body
    /// here), from the contacts' bodies (candidate, deformable antagonist) in the
    /// family's order: a body is stepped by the rank solving most of its contacts
    /// (the lowest of those tied), decided from each rank's count of the sides of
    /// the contacts it solves, per body (one all-gather of those counts: a rank
    /// reads no other rank's contacts). Whether the family is stepped in part.
    /// `ht`: the step's h and θ.
    pub fn decide(
        &mut self,
        n: usize,
        on: Option<&SolvedOn<'_>>,
        contacts: impl Iterator<Item = (u32, Option<u32>)>,
        ht: (f64, f64),
    ) -> bool {
        self.held = false;
        self.failed = false;
        self.energy_known = false;
        self.ht = ht;
        self.release.clear();
        let Some(on) = on else {
            self.on = None;
            return false;
        };
        self.on = Some((on.rank, on.ranks));
        self.solved.clear();
        self.rank.clear();
        for v in [&mut self.mine, &mut self.touched, &mut self.shared] {
            v.clear();
            v.resize(n, false);
        }
        std::mem::swap(&mut self.prev, &mut self.sender);
        self.sender.clear();
        self.sender.resize(n, u32::MAX);
        // (body, sides of its contacts solved here), once per contact side
        let mut here = Vec::new();
        for (a, (c, f)) in contacts.enumerate() {
            let r = (on.rank_of)(a);
            self.solved.push(r == on.rank);
            self.rank.push(r);
            if r == on.rank {
                for x in std::iter::once(c).chain(f).filter(|&x| (x as usize) < n) {
                    here.push(x);
                    self.touched[x as usize] = true;
                }
            }
        }
        here.sort_unstable();
        let mine: Vec<f64> = here
            .chunk_by(|a, b| a == b)
            .flat_map(|run| [f64::from(run[0]), run.len() as f64])
            .collect();
        // every rank's counts (one all-gather: no rank reads another's contacts)
        let mut by_body: Vec<(u32, u32, usize)> = Vec::new();
        for (r, m) in on.rounds.all_gather(&mine).iter().enumerate() {
            by_body.extend(m.chunks_exact(2).map(|x| (x[0] as u32, r as u32, x[1] as usize)));
        }
        by_body.retain(|x| (x.0 as usize) < n);
        by_body.sort_unstable();
        // a body is stepped by the rank solving most of its contacts (the lowest of
        // those tied), the other ranks solving some receive its columns
        self.solvers.clear();
        for run in by_body.chunk_by(|a, b| a.0 == b.0) {
            let x = run[0].0 as usize;
            let mut best = (0usize, u32::MAX);
            for &(_, r, k) in run {
                if k > best.0 {
                    best = (k, r);
                }
            }
            self.sender[x] = best.1;
            self.shared[x] = run.len() > 1;
            if self.shared[x] {
                self.solvers.extend(run.iter().map(|&(b, r, _)| (b, r)));
            }
        }
        for (b, s) in self.sender.iter_mut().enumerate() {
            if *s == u32::MAX {
                // (the rank that checked it at load: [`crate::scene::bodies_from`])
                *s = crate::scene::checked_by(b, n, on.ranks);
            }
            self.mine[b] = *s == on.rank;
        }
        let (_, after, matrices_after) = release_rule();
        self.idle.resize(n, after - 1);
        for (b, (i, &m)) in self.idle.iter_mut().zip(&self.mine).enumerate() {
            *i = if m { 0 } else { i.saturating_add(1) };
            if *i == after || *i == matrices_after {
                self.release.push((b as u32, *i == matrices_after));
            }
        }
        true
    }

    /// The bodies whose factors, columns of M̂⁻¹ and G this rank may drop now (after
    /// [`Self::decide`]: [`RELEASE_AFTER`] steps unstepped here), each with whether
    /// its M and K go too ([`RELEASE_MATRICES_AFTER`]).
    pub fn to_release(&self) -> &[(u32, bool)] {
        &self.release
    }

    /// Drops the columns and G of [`Self::to_release`]'s bodies, and the factors of
    /// M̂ (and M and K, as it says) of those large enough
    /// ([`crate::scene::is_large`]: [`RELEASE_MIN_BYTES`]); a smaller body's M,
    /// K and factors go only when it says so and the body is far from this
    /// rank's cells ([`crate::near::Near::holds`]: held stale).
    pub fn release<const D: usize>(&self, bodies: &mut [FeBody], sets: &mut [NodeSet<D>]) {
        for &(b, matrices) in &self.release {
            let body = &mut bodies[b as usize];
            match (crate::scene::is_large(body), matrices) {
                (false, _) => body.release_columns(),
                (true, false) => body.release_factor(),
                (true, true) => body.release_matrices(),
            }
            sets[b as usize].release_g();
        }
        // (a small body idle that long, once it is far from this rank's cells)
        let (_, _, matrices_after) = release_rule();
        for (b, body) in bodies.iter_mut().enumerate() {
            let idle = self.idle.get(b).is_some_and(|&i| i >= matrices_after);
            if idle && body.has_matrices() && !self.near.holds(b) && !crate::scene::is_large(body) {
                body.release_matrices();
            }
        }
    }

    /// Which bodies this rank steps (`None`: all of them).
    pub fn mask(&self) -> Option<&[bool]> {
        (self.held || self.failed || self.on.is_some()).then_some(&self.mine[..])
    }

    /// [`Self::mask`] and the bodies whose boundary this rank holds current
    /// ([`crate::near::Near::held`]).
    pub fn masks(&self) -> crate::stage2::Masks<'_> {
        (self.mask(), self.near.held())
    }

    /// Whether this rank solves each contact of the family's list, stepped in part
    /// (after [`Self::decide`]; `None`: all of them, in one process and before the
    /// partition).
    pub fn solved(&self) -> Option<&[bool]> {
        (self.on.is_some() && !self.held).then_some(&self.solved[..])
    }

    /// A failure in the step on this rank after [`Self::decide`] (the assembly or
    /// factorization of a body it steps; the step's end reports it): no body is
    /// stepped here any more and nothing of them is sent ([`crate::near::share`],
    /// [`crate::solved::pack_solved`]), but this rank still exchanges (empty
    /// messages) with the ranks it would have, so that none waits for it.
    pub fn fail(&mut self) {
        self.failed = true;
        self.energy_known = false;
        self.mine.fill(false);
    }

    /// Whether this rank sends body `b`'s columns at its contact nodes and its
    /// free velocity there to the other ranks solving its contacts (it steps the
    /// body, and another rank solves one of its contacts).
    pub fn sends(&self, b: usize) -> bool {
        self.on.is_some() && !self.held && self.mine[b] && self.shared[b]
    }

    /// Whether this rank solves one of body `b`'s contacts without stepping it (it
    /// receives what [`Self::sends`] sends).
    pub fn receives(&self, b: usize) -> bool {
        self.on.is_some() && !self.held && self.touched[b] && !self.mine[b]
    }

    /// This rank, in a step stepped in part after [`Self::decide`].
    pub fn rank_here(&self) -> Option<u32> {
        self.on.filter(|_| !self.held).map(|x| x.0)
    }

    /// The rank solving contact `a` (the family's list), after [`Self::decide`] in
    /// part.
    pub fn rank_of(&self, a: usize) -> u32 {
        self.rank[a]
    }

    /// The rank stepping body `b`, after [`Self::decide`] in part.
    pub fn sender(&self, b: usize) -> u32 {
        self.sender[b]
    }

    /// (body, rank solving one of its contacts) of the bodies whose contacts
    /// several ranks solve, ascending, once each, after [`Self::decide`] in part.
    pub fn solvers(&self) -> &[(u32, u32)] {
        &self.solvers
    }

    /// Whether this rank steps body `b`.
    pub fn steps(&self, b: usize) -> bool {
        self.mask().is_none_or(|m| m[b])
    }

    /// The bodies whose M and K this rank holds, stepped in part
    /// ([`nscdd::dd::Attached::built_bodies`]).
    pub fn built(&self, bodies: &[FeBody]) -> Option<usize> {
        self.on.map(|_| bodies.iter().filter(|b| b.has_matrices()).count())
    }

    /// (bodies stepped here, bodies), stepped in part.
    pub fn counts(&self) -> Option<(usize, usize)> {
        self.on.map(|_| (self.mine.iter().filter(|&&x| x).count(), self.mine.len()))
    }

    /// (h, θ) of the step in progress, in part.
    pub fn ht(&self) -> (f64, f64) {
        self.ht
    }

    /// After the bodies' V⁺ were shared ([`crate::near::share`]): every body's
    /// energies after the step, as their stepping ranks computed them (on rank 0;
    /// elsewhere those of the bodies stepped here), and the contacts over the
    /// ranks (on rank 0; elsewhere this rank's).
    pub fn after_share(&mut self, energy: Vec<[f64; 3]>, total: usize) {
        self.energy = energy;
        self.energy_known = true;
        self.total = Some(total);
    }

    /// Whether this rank writes body `b`'s frame files (of `n` bodies; `loaded`:
    /// (this rank, ranks) of a run on MPI ranks): the rank that stepped it last,
    /// which holds it whole, or before any step the rank that checked it at load
    /// (every rank holds it whole then); in one process, every body.
    pub fn writes_frame(&self, b: usize, n: usize, loaded: Option<(u32, u32)>) -> bool {
        let Some((me, p)) = loaded else { return true };
        match self.sender_of(b).filter(|_| self.on.is_some()) {
            Some(s) => s == me,
            None => crate::scene::checked_by(b, n, p) == me,
        }
    }

    /// The last step's stepping rank of body `b` (`None`: the state was whole on
    /// every rank, as after a load).
    pub fn prev_sender(&self, b: usize) -> Option<u32> {
        self.prev.get(b).copied().filter(|&p| p != u32::MAX)
    }

    /// (this rank, ranks) of the last step stepped in part.
    pub fn ranks(&self) -> Option<(u32, u32)> {
        self.on
    }

    /// The stepping rank of body `b` in the step in progress or the last one
    /// stepped in part.
    pub fn sender_of(&self, b: usize) -> Option<u32> {
        self.sender.get(b).copied()
    }

    /// The family's contacts over the ranks (the history's count, on rank 0),
    /// after the exchange of a step stepped in part.
    pub fn contacts_total(&self) -> Option<usize> {
        self.total
    }

    /// Every body's energies after the step, as their senders computed them
    /// ([`Self::after_share`]; on rank 0); `None` unless the step in progress was stepped in part and
    /// exchanged.
    pub fn energies(&self) -> Option<&[[f64; 3]]> {
        self.energy_known.then_some(&self.energy[..])
    }
}

/// The rounds of every rank simulated in one process (unit tests): the
/// all-gather gives every rank's sides per body from the whole list of contacts
/// (body, deformable antagonist) and their ranks; the point-to-point round gives
/// back `replies` (one message per peer, in order).
#[cfg(test)]
pub(crate) struct AllRanks<'a> {
    pub ranks: u32,
    pub rank_of: &'a dyn Fn(usize) -> u32,
    pub contacts: Vec<(u32, Option<u32>)>,
    pub replies: std::cell::RefCell<Vec<Vec<f64>>>,
    /// The point-to-point rounds' peers and messages sent, in order.
    pub sent: std::cell::RefCell<Vec<Sent>>,
}

/// A point-to-point round's peers and messages ([`AllRanks::sent`]).
#[cfg(test)]
pub(crate) type Sent = (Vec<u32>, Vec<Vec<f64>>);

#[cfg(test)]
impl<'a> AllRanks<'a> {
    /// `ranks` ranks, contact `a` (`contacts`' a-th) solved on `rank_of(a)`.
    pub fn new(ranks: u32, rank_of: &'a dyn Fn(usize) -> u32, contacts: Vec<(u32, Option<u32>)>) -> Self {
        AllRanks {
            ranks,
            rank_of,
            contacts,
            replies: Default::default(),
            sent: Default::default(),
        }
    }

    /// Rank `rank`'s view (each contact's subdomain its rank).
    pub fn on(&self, rank: u32) -> SolvedOn<'_> {
        SolvedOn {
            rank,
            ranks: self.ranks,
            rank_of: self.rank_of,
            subdomain_of: self.rank_of,
            rounds: self,
        }
    }

    /// Rank `me`'s decision over `n` bodies.
    pub fn decide(&self, me: u32, n: usize) -> Stepped {
        let mut s = Stepped::default();
        assert!(s.decide(n, Some(&self.on(me)), self.contacts.clone().into_iter(), (1e-3, 0.5)));
        s
    }
}

#[cfg(test)]
impl nscdd::dd::Rounds for AllRanks<'_> {
    fn all_gather(&self, _mine: &[f64]) -> Vec<Vec<f64>> {
        (0..self.ranks)
            .map(|r| {
                let mut m: std::collections::BTreeMap<u32, usize> = Default::default();
                for (_, (c, f)) in self.contacts.iter().enumerate().filter(|x| (self.rank_of)(x.0) == r) {
                    for x in std::iter::once(*c).chain(*f) {
                        *m.entry(x).or_default() += 1;
                    }
                }
                m.into_iter().flat_map(|(b, k)| [f64::from(b), k as f64]).collect()
            })
            .collect()
    }
    fn exchange(&self, peers: &[u32], out: &[Vec<f64>]) -> Vec<Vec<f64>> {
        self.sent.borrow_mut().push((peers.to_vec(), out.to_vec()));
        let mut r = self.replies.borrow_mut();
        (0..peers.len())
            .map(|i| r.get_mut(i).map(std::mem::take).unwrap_or_default())
            .collect()
    }
    /// (`replies[r]`: what rank r sends, if not empty)
    fn send(&self, to: Vec<(u32, Vec<f64>)>) -> Vec<(u32, Vec<f64>)> {
        self.sent.borrow_mut().push(to.into_iter().unzip());
        let got = std::mem::take(&mut *self.replies.borrow_mut());
        (0..).zip(got).filter(|x| !x.1.is_empty()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two bodies on 2 ranks: body 0's contact is solved on rank 1, body 1's on
    /// rank 0; seen from rank 0.
    fn decide(s: &mut Stepped, rank_of_0: u32) -> bool {
        let rank_of = |a: usize| if a == 0 { rank_of_0 } else { 0 };
        let contacts = vec![(0, None), (1, None)];
        let rounds = AllRanks::new(2, &rank_of, contacts.clone());
        s.decide(2, Some(&rounds.on(0)), contacts.into_iter(), (1e-3, 0.5))
    }

    #[test]
    fn a_body_unstepped_here_is_released_once_after_release_after_steps() {
        let mut s = Stepped::default();
        // never stepped here since the load: its factors released at the first step,
        // its matrices RELEASE_MATRICES_AFTER − RELEASE_AFTER steps later
        for step in 1..=RELEASE_MATRICES_AFTER {
            assert!(decide(&mut s, 1));
            assert!(!s.steps(0) && s.steps(1));
            let expect: &[(u32, bool)] = match step {
                1 => &[(0, false)],
                _ if step == RELEASE_MATRICES_AFTER - RELEASE_AFTER + 1 => &[(0, true)],
                _ => &[],
            };
            assert_eq!(s.to_release(), expect, "step {step}");
        }
        // stepped, then idle: its factors after RELEASE_AFTER steps, its matrices
        // after RELEASE_MATRICES_AFTER
        assert!(decide(&mut s, 0));
        for step in 1..=RELEASE_MATRICES_AFTER + 3 {
            assert!(decide(&mut s, 1));
            assert!(!s.steps(0) && s.steps(1));
            let expect: &[(u32, bool)] = match step {
                RELEASE_AFTER => &[(0, false)],
                RELEASE_MATRICES_AFTER => &[(0, true)],
                _ => &[],
            };
            assert_eq!(s.to_release(), expect, "step {step}");
        }
        // stepped here again: the count starts over
        assert!(decide(&mut s, 0));
        assert!(s.steps(0) && s.to_release().is_empty());
        for _ in 1..RELEASE_AFTER {
            decide(&mut s, 1);
            assert!(s.to_release().is_empty());
        }
        decide(&mut s, 1);
        assert_eq!(s.to_release(), &[(0, false)]);
        // one process: nothing stepped in part, nothing released
        assert!(!s.decide(2, None, std::iter::empty(), (1e-3, 0.5)));
        assert!(s.to_release().is_empty() && s.energies().is_none());
    }

    /// The contacts solved here: those of the rank's subdomains after the
    /// partition, none before it (every contact built) nor in one process
    /// ([`crate::solved`] builds them).
    #[test]
    fn the_contacts_solved_here() {
        let mut s = Stepped::default();
        s.hold(2);
        assert!(s.solved().is_none(), "before the partition");
        decide(&mut s, 1);
        assert_eq!(s.solved(), Some(&[false, true][..]));
        decide(&mut s, 0);
        assert_eq!(s.solved(), Some(&[true, true][..]));
        assert!(!s.decide(2, None, std::iter::empty(), (1e-3, 0.5)));
        assert!(s.solved().is_none(), "one process");
    }
}
