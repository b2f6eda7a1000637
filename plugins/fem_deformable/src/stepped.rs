//! The deformable bodies one MPI rank steps (docs/SCALING.md, "Deformable bodies
//! stepped per rank"). On an NSCDD step the family builds its contact list before
//! the partition without any solve ([`Stepped::hold`]: no body stepped yet); after
//! it the framework tells the family which rank solves each contact
//! ([`nscdd::dd::SolvedOn`]), and only a rank solving some of a body's contacts
//! computes the body's V_free, its columns of M̂⁻¹, its W_αα and u_free (the list
//! built again, the same) and its V⁺. A body without contact is stepped by rank
//! `b mod P`. Every rank still detects every contact and builds every part
//! (positions, V⁻ and the impulses are the same on every rank). After the
//! write-back, the first rank stepping a body sends its V⁺ to every rank
//! ([`Stepped::pack`], [`Stepped::unpack`]) with the body's energies after the
//! step (the history's columns, each body's computed once); the contacts'
//! impulses, u_free and targets come with their parts' results, from the rank that
//! solved them ([`crate::nodes::FeContacts::pack_results`]). A body not stepped
//! here builds no G (its contacts' W_αα and parts are never used here), and
//! once it has gone [`RELEASE_AFTER`] steps unstepped here the factors of its M̂,
//! its columns of M̂⁻¹ and its G are dropped (memory per rank; stepped again, it
//! factors and solves them anew, the same numbers). Loaded on ranks, a rank
//! holds the matrices of the bodies it checked at load only
//! ([`crate::scene::bodies_from`]), until the first step: a body it does not step
//! then is dropped at once, and one it steps without holding them is assembled and
//! factored there ([`crate::stage2::free_velocities`]).

use crate::body::FeBody;
use crate::nodes::NodeSet;
use nscdd::dd::SolvedOn;

/// Steps a body goes unstepped on a rank before the rank drops its factors of M̂,
/// its columns of M̂⁻¹ and its G (a body stepped on alternate steps keeps them).
pub const RELEASE_AFTER: u32 = 10;

/// Which bodies this rank steps in the step in progress (module docs).
#[derive(Default)]
pub struct Stepped {
    /// Stepped in part: (this rank, ranks); `mine` is then the mask.
    on: Option<(u32, u32)>,
    /// Before the partition of an NSCDD step: no body stepped yet.
    held: bool,
    /// Per body, in part: whether this rank steps it.
    mine: Vec<bool>,
    /// Per body, in part: the rank whose V⁺ every rank takes.
    sender: Vec<u32>,
    /// (h, θ) of the step in progress, in part.
    ht: (f64, f64),
    /// Per body, after the exchange of a step stepped in part: its energies after
    /// the step ([`FeBody::energies`] at u⁺, V⁺), as its sender computed them.
    energy: Vec<[f64; 3]>,
    energy_known: bool,
    /// Per body, in part: the steps since this rank last stepped it (a body not
    /// stepped here since the load counts RELEASE_AFTER − 1 at the first step).
    idle: Vec<u32>,
    /// The bodies that have just reached [`RELEASE_AFTER`] idle steps.
    release: Vec<u32>,
}

impl Stepped {
    /// Before the partition: the contact list is built without any body stepped
    /// (no solve), until [`Self::decide`].
    pub fn hold(&mut self, n: usize) {
        self.on = None;
        self.held = true;
        self.energy_known = false;
        self.mine.clear();
        self.mine.resize(n, false);
    }

    /// After the partition ([`nscdd::dd::Attached::solved_on`]; `None`: every body
    /// here), from the contacts' bodies (candidate, deformable antagonist) in the
    /// family's order: a body is stepped by every rank solving one of its contacts.
    /// Whether the family is stepped in part. `ht`: the step's h and θ.
    pub fn decide(
        &mut self,
        n: usize,
        on: Option<&SolvedOn<'_>>,
        contacts: impl Iterator<Item = (u32, Option<u32>)>,
        ht: (f64, f64),
    ) -> bool {
        self.held = false;
        self.energy_known = false;
        self.ht = ht;
        self.release.clear();
        let Some(on) = on else {
            self.on = None;
            return false;
        };
        self.on = Some((on.rank, on.ranks));
        self.mine.clear();
        self.mine.resize(n, false);
        self.sender.clear();
        self.sender.resize(n, u32::MAX);
        for (a, (c, f)) in contacts.enumerate() {
            let r = (on.rank_of)(a);
            for x in std::iter::once(c).chain(f) {
                let x = x as usize;
                self.sender[x] = self.sender[x].min(r);
                self.mine[x] |= r == on.rank;
            }
        }
        for (b, (s, m)) in self.sender.iter_mut().zip(self.mine.iter_mut()).enumerate() {
            if *s == u32::MAX {
                *s = (b % on.ranks as usize) as u32;
                *m = *s == on.rank;
            }
        }
        self.idle.resize(n, RELEASE_AFTER - 1);
        for (b, (i, &m)) in self.idle.iter_mut().zip(&self.mine).enumerate() {
            *i = if m { 0 } else { i.saturating_add(1) };
            if *i == RELEASE_AFTER {
                self.release.push(b as u32);
            }
        }
        true
    }

    /// The bodies whose factors, columns of M̂⁻¹ and G this rank may drop now (after
    /// [`Self::decide`]: [`RELEASE_AFTER`] steps unstepped here).
    pub fn to_release(&self) -> &[u32] {
        &self.release
    }

    /// Drops M, K, the factors of M̂, the columns and G of [`Self::to_release`]'s
    /// bodies.
    pub fn release<const D: usize>(&self, bodies: &mut [FeBody], sets: &mut [NodeSet<D>]) {
        for &b in &self.release {
            bodies[b as usize].release_matrices();
            sets[b as usize].release_g();
        }
    }

    /// Which bodies this rank steps (`None`: all of them).
    pub fn mask(&self) -> Option<&[bool]> {
        (self.held || self.on.is_some()).then_some(&self.mine[..])
    }

    /// Whether this rank steps body `b`.
    pub fn steps(&self, b: usize) -> bool {
        self.mask().is_none_or(|m| m[b])
    }

    /// (bodies stepped here, bodies), stepped in part.
    pub fn counts(&self) -> Option<(usize, usize)> {
        self.on.map(|_| (self.mine.iter().filter(|&&x| x).count(), self.mine.len()))
    }

    /// The bodies this rank sends: (body, its V⁺, its energies after the step) each,
    /// the energies at u⁺ ([`FeBody::u_next`], the position update's arithmetic).
    pub fn pack(&self, bodies: &[FeBody], out: &mut Vec<f64>) {
        let Some((rank, _)) = self.on else { return };
        let (h, theta) = self.ht;
        let mut u_next = Vec::new();
        for (b, body) in bodies.iter().enumerate().filter(|(b, _)| self.sender[*b] == rank) {
            out.push(b as f64);
            out.extend_from_slice(&body.v);
            u_next.clear();
            u_next.extend((0..body.u.len()).map(|i| body.u_next(i, h, theta)));
            out.extend(body.energies(&u_next, &body.v));
        }
    }

    /// Every rank's [`Self::pack`] (rank order): the V⁺ of the bodies not stepped
    /// here, every body's energies.
    pub fn unpack(&mut self, bodies: &mut [FeBody], all: &[f64]) {
        self.energy.clear();
        self.energy.resize(bodies.len(), [f64::NAN; 3]);
        let mut i = 0;
        while let Some(&b) = all.get(i) {
            let Some(body) = bodies.get_mut(b as usize) else { return };
            let n = body.v.len();
            let (Some(v), Some(e)) = (all.get(i + 1..i + 1 + n), all.get(i + 1 + n..i + 4 + n)) else {
                return;
            };
            if !self.steps(b as usize) {
                body.v.copy_from_slice(v);
            }
            self.energy[b as usize] = [e[0], e[1], e[2]];
            i += 4 + n;
        }
        self.energy_known = true;
    }

    /// Every body's energies after the step, as their senders computed them
    /// ([`Self::pack`]); `None` unless the step in progress was stepped in part and
    /// exchanged.
    pub fn energies(&self) -> Option<&[[f64; 3]]> {
        self.energy_known.then_some(&self.energy[..])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two bodies on 2 ranks: body 0's contact is solved on rank 1, body 1's on
    /// rank 0; seen from rank 0.
    fn decide(s: &mut Stepped, rank_of_0: u32) -> bool {
        let rank_of = |a: usize| if a == 0 { rank_of_0 } else { 0 };
        let on = SolvedOn {
            rank: 0,
            ranks: 2,
            rank_of: &rank_of,
        };
        s.decide(2, Some(&on), [(0, None), (1, None)].into_iter(), (1e-3, 0.5))
    }

    #[test]
    fn a_body_unstepped_here_is_released_once_after_release_after_steps() {
        let mut s = Stepped::default();
        // never stepped here since the load: released at the first step
        for step in 1..=3 {
            assert!(decide(&mut s, 1));
            assert!(!s.steps(0) && s.steps(1));
            let expect: &[u32] = if step == 1 { &[0] } else { &[] };
            assert_eq!(s.to_release(), expect, "step {step}");
        }
        assert!(decide(&mut s, 0));
        for step in 1..=RELEASE_AFTER + 3 {
            assert!(decide(&mut s, 1));
            assert!(!s.steps(0) && s.steps(1));
            let expect: &[u32] = if step == RELEASE_AFTER { &[0] } else { &[] };
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
        assert_eq!(s.to_release(), &[0]);
        // one process: nothing stepped in part, nothing released
        assert!(!s.decide(2, None, std::iter::empty(), (1e-3, 0.5)));
        assert!(s.to_release().is_empty() && s.energies().is_none());
    }
}
