//! The deformable bodies one MPI rank steps (docs/SCALING.md, "Deformable bodies
//! stepped per rank"): with contacts held per rank, between repartitions, the
//! framework tells the family where each contact will be solved
//! ([`nscdd::dd::RankView`]). Every rank still detects every contact and builds
//! every part (positions, V⁻ and the impulses are the same on every rank), but only
//! a rank solving some of a body's contacts computes the body's V_free, its
//! columns of M̂⁻¹, its W_αα and its V⁺. A body without contact is stepped by rank
//! `b mod P`. After the write-back, the first rank stepping a body sends its V⁺ to
//! every rank ([`Stepped::pack`], [`Stepped::unpack`]); the contacts' impulses,
//! u_free and targets come with their parts' results, from the rank that solved
//! them ([`crate::nodes::FeContacts::pack_results`]).

use crate::body::FeBody;
use nscdd::dd::RankView;

/// This step's view and, with one, each body's stepping ranks (module docs).
#[derive(Default)]
pub struct Stepped {
    view: Option<RankView>,
    /// Per body, with a view: whether this rank steps it.
    mine: Vec<bool>,
    /// Per body, with a view: the rank whose V⁺ every rank takes.
    sender: Vec<u32>,
}

impl Stepped {
    /// The step's view ([`nscdd::dd::Attached::set_ranks`]); whether the family is
    /// stepped in part.
    pub fn set(&mut self, view: Option<RankView>) -> bool {
        self.view = view;
        self.mine.clear();
        self.sender.clear();
        self.view.is_some()
    }

    /// With a view, from the step's raw contacts (point (z = 0 in 2D), candidate
    /// body, deformable antagonist body): a body is stepped by every rank solving
    /// one of its contacts.
    pub fn decide(&mut self, n: usize, contacts: impl Iterator<Item = ([f64; 3], u32, Option<u32>)>) {
        let Some(v) = &self.view else { return };
        self.mine = vec![false; n];
        self.sender = vec![u32::MAX; n];
        for (p, a, b) in contacts {
            let r = v.rank_of(p);
            for x in std::iter::once(a).chain(b) {
                let x = x as usize;
                self.sender[x] = self.sender[x].min(r);
                self.mine[x] |= r == v.rank;
            }
        }
        for (b, (s, m)) in self.sender.iter_mut().zip(self.mine.iter_mut()).enumerate() {
            if *s == u32::MAX {
                *s = (b % v.ranks as usize) as u32;
                *m = *s == v.rank;
            }
        }
    }

    /// Which bodies this rank steps (`None`: all of them).
    pub fn mask(&self) -> Option<&[bool]> {
        (self.view.is_some()).then_some(&self.mine[..])
    }

    /// Whether this rank steps body `b`.
    pub fn steps(&self, b: usize) -> bool {
        self.mask().is_none_or(|m| m[b])
    }

    /// (bodies stepped here, bodies), with a view.
    pub fn counts(&self) -> Option<(usize, usize)> {
        self.mask().map(|m| (m.iter().filter(|&&x| x).count(), m.len()))
    }

    /// V⁺ of the bodies this rank sends: (body, its V⁺) each.
    pub fn pack(&self, bodies: &[FeBody], out: &mut Vec<f64>) {
        let Some(v) = &self.view else { return };
        for (b, body) in bodies.iter().enumerate().filter(|(b, _)| self.sender[*b] == v.rank) {
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
