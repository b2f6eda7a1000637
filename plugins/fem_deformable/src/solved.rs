//! The contacts one MPI rank solves, and the columns of M̂⁻¹ it sends or receives
//! for them (docs/SCALING.md, "The contacts solved per rank" and "A body whose
//! contacts several ranks solve, stepped by one"). In a step stepped in part
//! ([`crate::stepped`]), a rank builds again with their numbers only the contacts
//! it solves ([`Solved`]); a body whose contacts several ranks solve is stepped by
//! one of them, which sends the others its free velocity at its contact nodes and
//! the rows of G their contacts read ([`pack_solved`], [`unpack_solved`], through
//! [`nscdd::dd::Attached::pack_solved`]).

use crate::nodes::{FeSide, NodeSet};
use crate::stepped::Stepped;

/// The bodies stepped here whose contacts other ranks solve too, each as (body,
/// its free velocity at its contact nodes, and the rows of G of the nodes the
/// receiver's contacts touch: [`NodeSet::pack_received`]), in a message to each of
/// those ranks; an empty message to the rank stepping a body whose contacts this
/// rank solves (the relation is symmetric, as
/// [`nscdd::dd::Attached::pack_solved`] needs). `sides`: the deformable sides of
/// the family's contacts, (contact, side).
pub fn pack_solved<const D: usize>(
    stepped: &Stepped,
    sets: &[NodeSet<D>],
    sides: impl Iterator<Item = (usize, FeSide<D>)>,
    out: &mut Vec<(u32, Vec<f64>)>,
) {
    let Some(me) = stepped.rank_here() else {
        return;
    };
    // (body, receiving rank, node of the set) of the bodies sent, ascending, once
    let mut rows: Vec<(u32, u32, u32)> = sides
        .filter(|(a, s)| stepped.sends(s.body as usize) && stepped.rank_of(*a) != me)
        .flat_map(|(a, s)| s.k.map(|k| (s.body, stepped.rank_of(a), k)))
        .collect();
    rows.sort_unstable();
    rows.dedup();
    let mut to: std::collections::BTreeMap<u32, Vec<f64>> = Default::default();
    for run in stepped.solvers().chunk_by(|a, b| a.0 == b.0) {
        let b = run[0].0;
        let sender = stepped.sender(b as usize);
        if sender == me {
            // (an empty message after a failure here: [`crate::stepped::Stepped::fail`])
            for &(_, r) in run.iter().filter(|x| x.1 != me) {
                let m = to.entry(r).or_default();
                if stepped.sends(b as usize) {
                    let lo = rows.partition_point(|x| (x.0, x.1) < (b, r));
                    let hi = rows.partition_point(|x| (x.0, x.1) <= (b, r));
                    let ks: Vec<u32> = rows[lo..hi].iter().map(|x| x.2).collect();
                    m.push(f64::from(b));
                    sets[b as usize].pack_received(&ks, m);
                }
            }
        } else if run.iter().any(|x| x.1 == me) {
            to.entry(sender).or_default();
        }
    }
    out.extend(to);
}

/// The messages of [`pack_solved`]: the bodies whose contacts this rank solves
/// without stepping them get their sender's free velocity and G
/// ([`NodeSet::set_received`]; every rank holds the same node sets).
pub fn unpack_solved<const D: usize>(stepped: &Stepped, sets: &mut [NodeSet<D>], from: &[(u32, Vec<f64>)]) {
    let mut got = vec![false; sets.len()];
    for (_, all) in from {
        let mut i = 0;
        // (body, v: D n, m, m nodes, their m D rows of D n values) each
        while let Some(&b) = all.get(i) {
            let Some(set) = sets.get_mut(b as usize) else { break };
            let nv = D * set.len();
            let Some(&m) = all.get(i + 1 + nv) else { break };
            let (ks, rows) = (i + 2 + nv, i + 2 + nv + m as usize);
            let end = rows + m as usize * D * nv;
            if all.len() < end {
                break;
            }
            if stepped.receives(b as usize) {
                set.set_received(&all[i + 1..i + 1 + nv], &all[ks..rows], &all[rows..end]);
                got[b as usize] = true;
            }
            i = end;
        }
    }
    // (a body whose sender failed in the step, which reports it: G and V_free 0)
    for (_, set) in sets.iter_mut().enumerate().filter(|(b, _)| stepped.receives(*b) && !got[*b]) {
        set.forget_g();
    }
}

/// The contacts this rank solves in a step stepped in part ([`Stepped::solved`]):
/// built again after the partition with their numbers (W_αα, u_free, targets),
/// while the family's list keeps every contact as one process has it (keys,
/// sides, frames and, after the step, every impulse: [`crate::family2`]'s parts
/// of other ranks' subdomains receive them).
#[derive(Default)]
pub struct Solved<Cs> {
    /// Each raw contact's index in the family's list (`u32::MAX`: dropped), from
    /// the build of the whole list.
    pub raw_at: Vec<u32>,
    /// The contacts solved here.
    pub list: Cs,
    /// Their indices in the family's list (ascending).
    pub at: Vec<u32>,
    /// Per contact of the family's list, its index in `list` (`u32::MAX`: solved
    /// elsewhere).
    pub of: Vec<u32>,
}

impl<Cs> Solved<Cs> {
    /// After a build of the contacts solved here (`at` filled): `of` for a family
    /// list of `n` contacts.
    pub fn index(&mut self, n: usize) {
        self.of.clear();
        self.of.resize(n, u32::MAX);
        for (l, &a) in self.at.iter().enumerate() {
            self.of[a as usize] = l as u32;
        }
    }

    /// A build's contacts `c` (`n`: their count): the family's list `list` (`own`
    /// false: every contact), or the contacts solved here, one for each of `at`.
    pub fn keep(&mut self, c: Cs, list: &mut Cs, own: bool, n: impl Fn(&Cs) -> usize) {
        debug_assert!(!own || self.at.len() == n(&c), "the contacts solved here built again");
        match own {
            false => *list = c,
            true => {
                self.list = c;
                self.index(n(list));
            }
        }
    }

    /// Whether raw contact `i` is to be built again here (`own`: the family's
    /// contacts solved here), its list index recorded in `at` if so.
    pub fn again(&mut self, i: usize, own: &[bool]) -> bool {
        match self.raw_at.get(i) {
            Some(&a) if a != u32::MAX && own[a as usize] => {
                self.at.push(a);
                true
            }
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nscdd::dd::SolvedOn;

    /// The contacts solved here are built again from the raw contacts kept in the
    /// family's list.
    #[test]
    fn the_contacts_solved_here_and_their_places() {
        // raw contacts 0, 2, 3 are the list's 0, 1, 2 (raw 1 dropped); list 1 is
        // solved elsewhere
        let mut sv = Solved::<()> {
            raw_at: vec![0, u32::MAX, 1, 2],
            ..Default::default()
        };
        let own = [true, false, true];
        let again: Vec<bool> = (0..4).map(|i| sv.again(i, &own)).collect();
        assert_eq!(again, [true, false, false, true]);
        assert_eq!(sv.at, [0, 2]);
        sv.index(3);
        assert_eq!(sv.of, [0, u32::MAX, 1]);
    }

    /// A body whose contacts ranks 0 (two) and 1 (one) solve, on 3 ranks: rank 0
    /// steps it and sends its free velocity and G to rank 1 alone, which lists rank
    /// 0 with an empty message (symmetric), and takes them; rank 2 sends nothing.
    #[test]
    fn a_shared_body_is_stepped_once_and_its_columns_sent() {
        let rank_of = |a: usize| if a < 2 { 0 } else { 1 };
        let decide_on = |me: u32| {
            let mut s = Stepped::default();
            let on = SolvedOn {
                rank: me,
                ranks: 3,
                rank_of: &rank_of,
            };
            assert!(s.decide(1, Some(&on), [(0, None); 3].into_iter(), (1e-3, 0.5)));
            s
        };
        let [s0, s1, s2] = [0, 1, 2].map(decide_on);
        assert!(s0.steps(0) && !s1.steps(0) && !s2.steps(0));
        assert!(s0.sends(0) && s1.receives(0) && !s2.receives(0));
        let mut set = NodeSet::<2>::default();
        set.nodes = vec![4];
        set.v = vec![[1.0, 2.0]];
        set.g = vec![3.0, 4.0, 5.0, 6.0];
        let packed = |s: &Stepped| {
            let mut out = Vec::new();
            let sides = (0..3).map(|a| (a, FeSide::node(0, 0)));
            pack_solved(s, std::slice::from_ref(&set), sides, &mut out);
            out
        };
        let (p0, p1, p2) = (packed(&s0), packed(&s1), packed(&s2));
        // (body 0, v, one node: set index 0, its two rows of G)
        assert_eq!(p0, [(1, vec![0.0, 1.0, 2.0, 1.0, 0.0, 3.0, 4.0, 5.0, 6.0])]);
        assert_eq!(p1, [(0, vec![])]);
        assert!(p2.is_empty());
        let mut got = vec![NodeSet::<2>::default()];
        got[0].nodes = vec![4];
        unpack_solved(&s1, &mut got, &[(0, p0[0].1.clone())]);
        assert_eq!((got[0].v.clone(), got[0].g.clone()), (set.v.clone(), set.g.clone()));
        // two contact nodes, rank 1's contact at the second only: only its rows of G
        // are sent, the others read 0 there
        let mut two = NodeSet::<2>::default();
        two.nodes = vec![4, 7];
        two.v = vec![[1.0, 2.0], [3.0, 4.0]];
        two.g = (0..16).map(f64::from).collect();
        let mut out = Vec::new();
        let sides = [(0, FeSide::node(0, 0)), (1, FeSide::node(0, 0)), (2, FeSide::node(0, 1))];
        pack_solved(&s0, std::slice::from_ref(&two), sides.into_iter(), &mut out);
        let mut rows: Vec<f64> = vec![0.0, 1.0, 2.0, 3.0, 4.0, 1.0, 1.0];
        rows.extend((8..16).map(f64::from));
        assert_eq!(out, [(1, rows.clone())]);
        let mut got2 = vec![NodeSet::<2>::default()];
        got2[0].nodes = vec![4, 7];
        unpack_solved(&s1, &mut got2, &[(0, rows)]);
        assert_eq!(got2[0].v, two.v);
        assert_eq!(got2[0].block(1, 0), two.block(1, 0));
        assert_eq!(got2[0].block(1, 1), two.block(1, 1));
        assert_eq!(got2[0].block(0, 0), [[0.0; 2]; 2]);
        // rank 0 fails in the step (its body's assembly): it steps nothing, sends
        // nothing of the body and no V⁺, but still exchanges with rank 1 (an empty
        // message), whose set then reads no G and zero velocities
        let mut f0 = decide_on(0);
        f0.fail();
        assert!(!f0.steps(0) && !f0.sends(0) && f0.mask() == Some(&[false][..]));
        assert_eq!(packed(&f0), [(1, vec![])]);
        let mut v = Vec::new();
        f0.pack(&[], &mut v);
        assert!(v.is_empty());
        unpack_solved(&s1, &mut got, &[(0, vec![])]);
        assert_eq!(got[0].v, [[0.0, 0.0]]);
        assert_eq!(got[0].block(0, 0), [[0.0; 2]; 2]);
    }
}
