//! The warm starts of the deformable contacts on MPI ranks (docs/SCALING.md, "Warm
//! starts from the stepping ranks"). One process starts each contact from its
//! impulse of the last step, found by key ([`crate::nodes::FeKey`]). On ranks a
//! contact's last impulse is kept by the rank that stepped its candidate body in
//! the last step, its home:
//!
//! ```text
//! step end (share_stepped):  each rank's contacts whose candidate body another
//!                            rank steps go there with the impulse shares
//!                            ([`crate::impulses`]); the stepping rank holds
//!                            (key, r) of every contact of its bodies
//! next step (solved_on):     a body whose stepping rank changes hands its
//!                            contacts over with its whole state
//!                            ([`crate::whole::hand_over`]); the rank stepping
//!                            a body sends each other rank solving its contacts
//!                            those at the nodes it asked for, with the columns
//!                            ([`crate::solved::share_columns`])
//! ```
//!
//! A contact solved on a rank has its candidate node among the nodes that rank
//! asked for, so every contact of the last step that a rank solves again finds
//! its impulse there: the one-process warm start, with no list of every
//! contact. Each message of these rounds starts with the warm starts it carries
//! ([`with_front`], [`split_front`]).

use crate::nodes::FeKey;
use std::collections::BTreeMap;

/// The last step's (key, r) this rank holds, by key.
#[derive(Clone, Debug)]
pub struct Warm<const N: usize> {
    /// Sorted by key, unique.
    pub held: Vec<(FeKey, [f64; N])>,
    /// The family's list holds the warm starts instead (before the first step on
    /// ranks, and after a load, which every rank reads whole).
    pub from_list: bool,
}

impl<const N: usize> Default for Warm<N> {
    fn default() -> Self {
        Warm {
            held: Vec::new(),
            from_list: true,
        }
    }
}

impl<const N: usize> Warm<N> {
    /// The values of one entry in a message: key and r.
    pub const LEN: usize = 4 + N;

    /// After a load: the family's list holds the warm starts.
    pub fn loaded(&mut self) {
        self.held.clear();
        self.from_list = true;
    }

    /// At a step's end: the contacts of the bodies this rank stepped, `entries`
    /// (this rank's and those received, any order; r = 0 left out).
    pub fn set(&mut self, entries: impl Iterator<Item = (FeKey, [f64; N])>) {
        self.held.clear();
        self.held.extend(entries.filter(|e| e.1 != [0.0; N]));
        self.held.sort_unstable_by_key(|e| e.0);
        self.held.dedup_by_key(|e| e.0);
        self.from_list = false;
    }

    /// Entries received (a hand-over, the columns' round), added.
    pub fn add(&mut self, m: &[f64]) {
        if m.is_empty() {
            return;
        }
        self.held.extend(unpack::<N>(m));
        self.held.sort_unstable_by_key(|e| e.0);
        self.held.dedup_by_key(|e| e.0);
    }

    /// The entries of body `b`'s contacts (as candidate), `at(node)` deciding
    /// which, packed into `m`.
    pub fn pack_body(&self, b: u32, at: impl Fn(u32) -> bool, m: &mut Vec<f64>) {
        let lo = self.held.partition_point(|e| e.0 .0 < b);
        for (k, r) in self.held[lo..].iter().take_while(|e| e.0 .0 == b) {
            if at(k.1) {
                pack(*k, *r, m);
            }
        }
    }

    /// The impulse of contact `key` in the last step (0 if it had none).
    pub fn r_of(&self, key: &FeKey) -> [f64; N] {
        match self.held.binary_search_by_key(key, |e| e.0) {
            Ok(p) => self.held[p].1,
            Err(_) => [0.0; N],
        }
    }
}

/// One entry (key, r) appended to `m`.
pub fn pack<const N: usize>(k: FeKey, r: [f64; N], m: &mut Vec<f64>) {
    m.extend([k.0, k.1, k.2, k.3].map(f64::from));
    m.extend(r);
}

/// The entries of `m` (whole entries only).
pub fn unpack<const N: usize>(m: &[f64]) -> impl Iterator<Item = (FeKey, [f64; N])> + '_ {
    m.chunks_exact(Warm::<N>::LEN).map(|x| {
        let k = (x[0] as u32, x[1] as u32, x[2] as u32, x[3] as u32);
        (k, std::array::from_fn(|q| x[4 + q]))
    })
}

/// Each message of `to` started by its peer's `front` (its length, then its
/// values; 0 if none). Every message of a round with fronts gets one, so that
/// [`split_front`] reads them all.
pub fn with_front(to: &mut BTreeMap<u32, Vec<f64>>, mut front: BTreeMap<u32, Vec<f64>>) {
    for (peer, m) in to.iter_mut() {
        let f = front.remove(peer).unwrap_or_default();
        let rest = std::mem::take(m);
        m.reserve(1 + f.len() + rest.len());
        m.push(f.len() as f64);
        m.extend(f);
        m.extend(rest);
    }
    debug_assert!(front.is_empty(), "warm starts for ranks outside the round");
}

/// A message of a round with fronts ([`with_front`]): (front, rest). An empty or
/// truncated message reads as empty.
pub fn split_front(m: &[f64]) -> (&[f64], &[f64]) {
    match m.first() {
        Some(&n) if (n as usize) < m.len() => (&m[1..1 + n as usize], &m[1 + n as usize..]),
        _ => (&[], &[]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_kept_by_key_and_a_body_packed_at_some_nodes() {
        let mut w = Warm::<2>::default();
        assert!(w.from_list);
        let e = |b, n, r: f64| ((b, n, 7, 0), [r, 0.5]);
        w.set([e(1, 4, 2.0), e(0, 3, 1.0), ((2, 1, 7, 0), [0.0, 0.0]), e(1, 2, 3.0)].into_iter());
        assert!(!w.from_list);
        assert_eq!(w.held.iter().map(|x| x.0 .1).collect::<Vec<_>>(), [3, 2, 4]);
        assert_eq!(w.r_of(&(1, 4, 7, 0)), [2.0, 0.5]);
        assert_eq!(w.r_of(&(2, 1, 7, 0)), [0.0, 0.0]);
        let mut m = Vec::new();
        w.pack_body(1, |n| n == 4, &mut m);
        assert_eq!(m, [1.0, 4.0, 7.0, 0.0, 2.0, 0.5]);
        let mut v = Warm::<2>::default();
        v.add(&m);
        v.add(&m);
        assert_eq!(v.held, [((1, 4, 7, 0), [2.0, 0.5])]);
        v.loaded();
        assert!(v.from_list && v.held.is_empty());
    }

    #[test]
    fn fronts_before_each_message_of_a_round() {
        let mut to: BTreeMap<u32, Vec<f64>> = [(1, vec![9.0]), (3, vec![])].into();
        with_front(&mut to, [(1, vec![5.0, 6.0])].into());
        assert_eq!(to[&1], [2.0, 5.0, 6.0, 9.0]);
        assert_eq!(to[&3], [0.0]);
        assert_eq!(split_front(&to[&1]), (&[5.0, 6.0][..], &[9.0][..]));
        assert_eq!(split_front(&to[&3]), (&[][..], &[][..]));
        assert_eq!(split_front(&[]), (&[][..], &[][..]));
        assert_eq!(split_front(&[4.0, 1.0]), (&[][..], &[][..]));
    }
}
