//! V⁺ of a deformable body from the impulses of its contacts, those solved on other
//! MPI ranks sent to the rank stepping it (docs/SCALING.md, "V⁺ from the
//! impulses sent to the stepping rank"). After the sweeps each rank holds the
//! impulses of the contacts it solved; a body stepped elsewhere gets, from each
//! rank solving some of its contacts, the shares of those impulses on its side
//! (the contact's key, the side's nodes and weights, the impulse P and its
//! sign), point to point, in [`nscdd::dd::Attached::share_stepped`]. The rank
//! stepping it adds them to its own contacts' in the one-process order (the
//! contacts in key order, the family's, the candidate side before the
//! antagonist): V⁺ is the one-process number.

use crate::nodes::{FeKey, FeSide, NodeSet};
use crate::stepped::Stepped;
use nscdd::dd::{RankCells, Rounds};
use std::collections::BTreeMap;

/// One side's share of a contact's impulse: the contact's key (its place in the
/// family's order), which side (0: candidate, 1: antagonist), the side, its sign
/// and the global impulse P on the candidate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Share<const D: usize> {
    pub key: FeKey,
    pub which: u32,
    pub side: FeSide<D>,
    pub sign: f64,
    pub p: [f64; D],
}

/// A contact solved here, as [`share`] takes it: its candidate side, its
/// deformable antagonist side, its impulse P (global), and its key (its place in
/// the family's order) and r (local: its next warm start, [`crate::warm`]).
pub type Own<const D: usize> = (FeSide<D>, Option<FeSide<D>>, [f64; D], (FeKey, [f64; D]));

/// The shares of the contacts solved here (`contacts`, in the family's order)
/// on the bodies other ranks step go to those ranks, with the (key, r) of those
/// whose candidate body another rank steps ([`crate::warm`]); returns the
/// shares on the bodies stepped here, this rank's and those received, in the
/// one-process order, and the (key, r) of the contacts of the bodies stepped
/// here. `sets`: the node sets (the sides' set indices; a set of a body stepped
/// here holds every node the other ranks' contacts touch,
/// [`crate::solved::shared_nodes`]).
pub fn share<const D: usize>(
    st: &Stepped,
    sets: &[NodeSet<D>],
    contacts: impl Iterator<Item = Own<D>>,
    rounds: &dyn Rounds,
) -> (Vec<Share<D>>, Vec<(FeKey, [f64; D])>) {
    let Some(me) = st.rank_here() else {
        return Default::default();
    };
    let (mut here, mut warm) = (Vec::new(), Vec::new());
    // (the ranks solving some contacts of a body stepped here, or stepping a body
    // some of whose contacts are solved here: the symmetric relation of the columns)
    let mut to = crate::solved::rounds_with(st, me, |_, _, _| {});
    let mut front: BTreeMap<u32, Vec<f64>> = BTreeMap::new();
    for (cand, anta, p, (key, r)) in contacts {
        match st.sender_of(cand.body as usize).unwrap_or(me) {
            q if q == me => warm.push((key, r)),
            q if r != [0.0; D] && to.contains_key(&q) => crate::warm::pack(key, r, front.entry(q).or_default()),
            _ => {}
        }
        for (which, side, sign) in [(0, Some(cand), 1.0), (1, anta, -1.0)] {
            let Some(side) = side else { continue };
            let q = st.sender_of(side.body as usize).unwrap_or(me);
            if q == me {
                here.push(Share { key, which, side, sign, p });
            } else if let Some(m) = to.get_mut(&q) {
                // (key, which, body, sign, the side's D nodes and weights, P)
                m.extend([key.0, key.1, key.2, key.3, which, side.body].map(f64::from));
                m.push(sign);
                let set = &sets[side.body as usize];
                m.extend(side.k.map(|k| f64::from(set.nodes[k as usize])));
                m.extend(side.w);
                m.extend(p);
            } else {
                debug_assert!(
                    false,
                    "body {} is stepped by rank {q}, which solves none of its contacts",
                    side.body
                );
            }
        }
    }
    let len = 7 + 3 * D;
    crate::warm::with_front(&mut to, front);
    for (_, m) in crate::solved::exchange_with(rounds, to) {
        let (got, m) = crate::warm::split_front(&m);
        warm.extend(crate::warm::unpack::<D>(got));
        for x in m.chunks_exact(len) {
            let body = x[5] as u32;
            let Some(set) = sets.get(body as usize).filter(|_| st.steps(body as usize)) else {
                continue;
            };
            let (nodes, w, p) = (&x[7..7 + D], &x[7 + D..7 + 2 * D], &x[7 + 2 * D..]);
            let k = std::array::from_fn(|q| {
                let found = set.nodes.binary_search(&(nodes[q] as u32));
                debug_assert!(
                    found.is_ok(),
                    "body {body}: node {} of a contact solved elsewhere not in its set",
                    nodes[q]
                );
                found.map_or(0, |k| k as u32)
            });
            here.push(Share {
                key: (x[0] as u32, x[1] as u32, x[2] as u32, x[3] as u32),
                which: x[4] as u32,
                side: FeSide {
                    body,
                    k,
                    w: std::array::from_fn(|q| w[q]),
                },
                sign: x[6],
                p: std::array::from_fn(|q| p[q]),
            });
        }
    }
    here.sort_by_key(|s| (s.key, s.which));
    (here, warm)
}

/// [`nscdd::dd::Attached::share_stepped`] of the deformable bodies: V⁺ of the
/// bodies stepped here from the shares of their contacts' impulses ([`share`];
/// `own`: the contacts solved here, as [`share`] takes them), the next step's
/// warm starts of their contacts into `warm`, then their V⁺ at their boundary to
/// the ranks near them (`next`: the cells of the next detection) with their
/// energies and the contacts solved here to rank 0 ([`crate::near::share`]),
/// and the node sets at V⁺ (the residual).
pub fn finish<const D: usize>(
    st: &mut Stepped,
    (bodies, alert): (&mut [crate::body::FeBody], f64),
    (sets, warm): (&mut [NodeSet<D>], &mut crate::warm::Warm<D>),
    own: impl Iterator<Item = Own<D>>,
    (rounds, next): (&dyn Rounds, Option<&RankCells<'_>>),
) {
    let own: Vec<_> = own.collect();
    let (shares, held) = share(st, sets, own.iter().copied(), rounds);
    warm.set(held.into_iter());
    crate::nodes::velocities_from(bodies, sets, shares.iter().map(|s| (s.side, s.sign, s.p)), st.mask());
    crate::near::share(st, bodies, (own.len(), alert), next, rounds);
    crate::nodes::sets_at_velocities(bodies, sets);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stepped::AllRanks;

    /// Body 0's two contacts (on rigid bodies) are solved on rank 0, which steps
    /// it, the contact of body 1 on body 0's segment on rank 1, which steps body
    /// 1: rank 1 sends the antagonist side's share to rank 0, which merges it
    /// with its own two in key order (the family's).
    #[test]
    fn a_body_stepped_here_gets_the_shares_of_its_contacts_solved_elsewhere() {
        let rank_of = |a: usize| u32::from(a == 1);
        let contacts = vec![(0, None), (1, Some(0)), (0, None)];
        let rounds = AllRanks::new(2, &rank_of, contacts);
        let (s0, s1) = (rounds.decide(0, 2), rounds.decide(1, 2));
        assert!(s0.steps(0) && s1.steps(1) && !s1.steps(0));
        let mut sets = vec![NodeSet::<2>::default(), NodeSet::<2>::default()];
        sets[0].nodes = vec![3, 8, 9];
        sets[1].nodes = vec![5];
        let seg = FeSide {
            body: 0,
            k: [1, 2],
            w: [0.25, 0.75],
        };
        // rank 1: its contact's candidate side on body 1 stays, the antagonist's goes
        let key1 = ((1, 5, 1 << 31, 0), [0.5, 0.0]);
        let own1 = [(FeSide::node(1, 0), Some(seg), [1.0, 2.0], key1)];
        let (here1, warm1) = share(&s1, &sets, own1.into_iter(), &rounds);
        assert_eq!(here1.iter().map(|s| (s.key, s.which)).collect::<Vec<_>>(), [(key1.0, 0)]);
        assert_eq!(warm1, [key1]);
        let sent = rounds.sent.borrow().last().cloned().unwrap();
        // (no warm start: the key, antagonist, body 0, sign −1, nodes 8 and 9, weights, P)
        let msg = vec![0.0, 1.0, 5.0, 2147483648.0, 0.0, 1.0, 0.0, -1.0, 8.0, 9.0, 0.25, 0.75, 1.0, 2.0];
        assert_eq!(sent, (vec![0], vec![msg]));
        // rank 0 receives it and merges it with its two contacts in key order
        *rounds.replies.borrow_mut() = sent.1.clone();
        let key = |n: u32| ((0, n, 7, 0), [1.0, 0.0]);
        let own0 = [
            (FeSide::node(0, 0), None, [3.0, 4.0], key(3)),
            (FeSide::node(0, 0), None, [5.0, 6.0], key(4)),
        ];
        let (here0, warm0) = share(&s0, &sets, own0.into_iter(), &rounds);
        assert_eq!(warm0, [key(3), key(4)]);
        assert_eq!(rounds.sent.borrow().last().cloned().unwrap(), (vec![1], vec![vec![0.0]]));
        let got: Vec<(FeKey, u32, f64)> = here0.iter().map(|s| (s.key, s.which, s.sign)).collect();
        assert_eq!(got, [(key(3).0, 0, 1.0), (key(4).0, 0, 1.0), (key1.0, 1, -1.0)]);
        assert_eq!(here0[2].side, seg);
        assert_eq!(here0[2].p, [1.0, 2.0]);
    }
}
