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
//! ([`Stepped::pack`], [`Stepped::unpack`]); the contacts' impulses, u_free and
//! targets come with their parts' results, from the rank that solved them
//! ([`crate::nodes::FeContacts::pack_results`]).

use crate::body::FeBody;
use nscdd::dd::SolvedOn;

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
}

impl Stepped {
    /// Before the partition: the contact list is built without any body stepped
    /// (no solve), until [`Self::decide`].
    pub fn hold(&mut self, n: usize) {
        self.on = None;
        self.held = true;
        self.mine.clear();
        self.mine.resize(n, false);
    }

    /// After the partition ([`nscdd::dd::Attached::solved_on`]; `None`: every body
    /// here), from the contacts' bodies (candidate, deformable antagonist) in the
    /// family's order: a body is stepped by every rank solving one of its contacts.
    /// Whether the family is stepped in part.
    pub fn decide(&mut self, n: usize, on: Option<&SolvedOn<'_>>, contacts: impl Iterator<Item = (u32, Option<u32>)>) -> bool {
        self.held = false;
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
        true
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

    /// V⁺ of the bodies this rank sends: (body, its V⁺) each.
    pub fn pack(&self, bodies: &[FeBody], out: &mut Vec<f64>) {
        let Some((rank, _)) = self.on else { return };
        for (b, body) in bodies.iter().enumerate().filter(|(b, _)| self.sender[*b] == rank) {
            out.push(b as f64);
            out.extend_from_slice(&body.v);
        }
    }

    /// Every rank's [`Self::pack`] (rank order): the V⁺ of the bodies not stepped
    /// here.
    pub fn unpack(&self, bodies: &mut [FeBody], all: &[f64]) {
        let mut i = 0;
        while let Some(&b) = all.get(i) {
            let Some(body) = bodies.get_mut(b as usize) else { return };
            let Some(v) = all.get(i + 1..i + 1 + body.v.len()) else { return };
            if !self.steps(b as usize) {
                body.v.copy_from_slice(v);
            }
            i += 1 + body.v.len();
        }
    }
}
