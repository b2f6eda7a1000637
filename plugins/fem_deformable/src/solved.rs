//! The contacts one MPI rank solves, and the columns of M̂⁻¹ it sends or receives
//! for them (docs/SCALING.md, "The contacts solved per rank" and "A body whose
//! contacts several ranks solve, stepped by one"). In a step stepped in part
//! ([`crate::stepped`]), a rank builds only the contacts it solves
//! ([`Solved`]); a body whose contacts several ranks solve is stepped by
//! one of them, which sends the others its free velocity at its contact nodes and
//! the rows of G their contacts read ([`share_columns`]: [`pack_solved`],
//! [`unpack_solved`], one point-to-point round in
//! [`nscdd::dd::Attached::solved_on`], with the contacts' warm starts,
//! [`crate::warm`]).

use crate::nodes::NodeSet;
use crate::stepped::Stepped;
use crate::warm::Warm;
use nscdd::dd::{Rounds, SolvedOn};
use std::collections::BTreeMap;

/// (body, rank, its nodes) that other ranks asked of the bodies this rank steps
/// ([`ask_nodes`]), ascending by (body, rank).
pub type Asked = Vec<(u32, u32, Vec<u32>)>;

/// This rank's peers in the rounds for the bodies whose contacts several ranks
/// solve, each with a message started: for a body it steps, the other ranks
/// solving its contacts; for a body whose contacts it solves without stepping it,
/// the rank stepping it (a symmetric relation). `fill(peer, body, message)` adds
/// to the message for each (peer, body) in turn.
pub(crate) fn rounds_with(stepped: &Stepped, me: u32, mut fill: impl FnMut(u32, u32, &mut Vec<f64>)) -> BTreeMap<u32, Vec<f64>> {
    let mut to: BTreeMap<u32, Vec<f64>> = BTreeMap::new();
    for run in stepped.solvers().chunk_by(|a, b| a.0 == b.0) {
        let b = run[0].0;
        let sender = stepped.sender(b as usize);
        if sender == me {
            for &(_, r) in run.iter().filter(|x| x.1 != me) {
                fill(r, b, to.entry(r).or_default());
            }
        } else if run.iter().any(|x| x.1 == me) {
            fill(sender, b, to.entry(sender).or_default());
        }
    }
    to
}

/// One point-to-point round of the messages `to` (by rank, ascending: a
/// symmetric relation, [`Rounds::exchange`]); returns (rank, its message) each.
pub fn exchange_with(rounds: &dyn Rounds, to: BTreeMap<u32, Vec<f64>>) -> Vec<(u32, Vec<f64>)> {
    let (peers, out): (Vec<u32>, Vec<Vec<f64>>) = to.into_iter().unzip();
    let inbox = rounds.exchange(&peers, &out);
    peers.into_iter().zip(inbox).collect()
}

/// The first round for the bodies whose contacts several ranks solve (after
/// [`Stepped::decide`], before the free velocities): each rank solving some of a
/// body's contacts without stepping it sends the rank stepping it the body's
/// nodes its contacts touch (mesh node ids), which that rank adds to the body's
/// contact nodes ([`shared_nodes`]) and sends the rows of G of ([`pack_solved`]).
/// `sides`: the deformable sides of the contacts solved here, (body, node).
/// Returns what the bodies stepped here were asked.
pub fn ask_nodes(stepped: &Stepped, sides: impl Iterator<Item = (u32, u32)>, rounds: &dyn Rounds) -> Asked {
    let mut asked = Asked::new();
    let Some(me) = stepped.rank_here() else {
        return asked;
    };
    let mut mine: Vec<(u32, u32)> = sides.filter(|s| stepped.receives(s.0 as usize)).collect();
    mine.sort_unstable();
    mine.dedup();
    let to = rounds_with(stepped, me, |peer, b, m| {
        if peer == stepped.sender(b as usize) {
            let lo = mine.partition_point(|x| x.0 < b);
            let hi = mine.partition_point(|x| x.0 <= b);
            m.extend([f64::from(b), (hi - lo) as f64]);
            m.extend(mine[lo..hi].iter().map(|x| f64::from(x.1)));
        }
    });
    for (r, m) in exchange_with(rounds, to) {
        // (body, count, its nodes) each
        let mut i = 0;
        while let (Some(&b), Some(&n)) = (m.get(i), m.get(i + 1)) {
            let Some(nodes) = m.get(i + 2..i + 2 + n as usize) else { break };
            if stepped.sends(b as usize) {
                asked.push((b as u32, r, nodes.iter().map(|&x| x as u32).collect()));
            }
            i += 2 + n as usize;
        }
    }
    asked.sort_unstable_by_key(|x| (x.0, x.1));
    asked
}

/// One deformable side of a contact: the body and the mesh nodes it reads (a
/// single node repeated).
pub type Side<const D: usize> = (u32, [u32; D]);

/// A contact's sides for the rounds of a step stepped in part: its candidate
/// side, its deformable antagonist side if any, its rigid antagonist (global id)
/// if any.
pub type Sides<const D: usize> = (Side<D>, Option<Side<D>>, Option<u32>);

/// [`nscdd::dd::Attached::solved_on`]'s rounds before the free velocities,
/// stepped in part: the whole states handed over ([`crate::whole::hand_over`]),
/// then the nodes of the bodies stepped elsewhere that the contacts solved here
/// touch asked of their stepping ranks ([`ask_nodes`]). `sides(a)`: the `n`
/// contacts of the family's list.
pub fn rounds_before<const D: usize>(
    st: &mut Stepped,
    (bodies, warm): (&mut [crate::body::FeBody], &mut Warm<D>),
    (n, sides): (usize, impl Fn(usize) -> Sides<D>),
    on: &SolvedOn<'_>,
) -> Asked {
    crate::whole::hand_over(st, bodies, warm, on.rounds);
    let own = (0..n).filter(|&a| st.rank_of(a) == on.rank);
    let fe = own.flat_map(|a| {
        let (c, f, _) = sides(a);
        std::iter::once(c).chain(f)
    });
    let nodes = fe.flat_map(|(b, ks)| ks.map(|k| (b, k)));
    ask_nodes(&*st, nodes, on.rounds)
}

/// [`nscdd::dd::Attached::solved_on`]'s rounds once the sets are filled, stepped
/// in part: the other ranks' subdomains and the node counts of the bodies every
/// rank steps ([`crate::shells::share`]), into `solved`, then the columns of the
/// bodies several ranks solve, with their contacts' warm starts
/// ([`share_columns`]).
pub fn rounds_after<const D: usize, Cs>(
    st: &Stepped,
    (sets, warm): (&mut [NodeSet<D>], &mut Warm<D>),
    (n, sides): (usize, impl Fn(usize) -> Sides<D>),
    on: &SolvedOn<'_>,
    solved: &mut Solved<Cs>,
) {
    let bodies = |a: usize| {
        let (c, f, r) = sides(a);
        (c.0, f.map(|s| s.0), r)
    };
    let filled = sets.iter().enumerate().filter(|(b, s)| st.steps(*b) && !s.is_empty());
    let stepped: Vec<(u32, u32)> = filled.map(|(b, s)| (b as u32, s.len() as u32)).collect();
    (solved.shells, solved.set_lens) = crate::shells::share(on, n, bodies, &stepped);
    share_columns(st, (sets, warm), &solved.asked, on.rounds);
}

/// The contact nodes of the bodies this rank steps whose contacts other ranks
/// solve too: the nodes of the contacts solved here (`raw`: (contact, body,
/// node) of every side of the family's contacts), and those the other ranks
/// asked ([`ask_nodes`]), into `nodes` (each body's sorted nodes). The others'
/// entries stay.
pub fn shared_nodes<Cs>(stepped: &Stepped, solved: &Solved<Cs>, raw: impl Iterator<Item = (usize, u32, u32)>, nodes: &mut [Vec<u32>]) {
    let Some(own) = stepped.solved() else {
        return;
    };
    let here = |i: usize| own.get(i).is_some_and(|&o| o);
    let mut pairs: Vec<(u32, u32)> = raw
        .filter(|&(i, b, _)| stepped.sends(b as usize) && here(i))
        .map(|x| (x.1, x.2))
        .collect();
    for (b, _, ns) in &solved.asked {
        pairs.extend(ns.iter().map(|&k| (*b, k)));
    }
    pairs.sort_unstable();
    pairs.dedup();
    for run in pairs.chunk_by(|a, b| a.0 == b.0) {
        let b = run[0].0 as usize;
        let union: Vec<u32> = run.iter().map(|x| x.1).collect();
        // (the contacts solved here hold a body's own nodes: a part of the union)
        debug_assert!(nodes[b].iter().all(|k| union.binary_search(k).is_ok()), "body {b}'s contact nodes");
        nodes[b] = union;
    }
}

/// The bodies stepped here whose contacts other ranks solve too, each as (body,
/// its contact nodes, its free velocity there, and the rows of G of the nodes the
/// receiver asked for: [`NodeSet::pack_received`]), in a message to each of those
/// ranks; an empty message to the rank stepping a body whose contacts this rank
/// solves (the relation is symmetric, as [`Rounds::exchange`] needs). `asked`:
/// [`ask_nodes`]'s.
pub fn pack_solved<const D: usize>(stepped: &Stepped, sets: &[NodeSet<D>], asked: &Asked, out: &mut Vec<(u32, Vec<f64>)>) {
    let Some(me) = stepped.rank_here() else {
        return;
    };
    // (an empty message after a failure here: [`crate::stepped::Stepped::fail`])
    let to = rounds_with(stepped, me, |r, b, m| {
        if stepped.sends(b as usize) {
            let set = &sets[b as usize];
            let at = asked.binary_search_by_key(&(b, r), |x| (x.0, x.1));
            let ks: Vec<u32> = at
                .map_or(&[][..], |p| &asked[p].2[..])
                .iter()
                .filter_map(|k| set.nodes.binary_search(k).ok().map(|k| k as u32))
                .collect();
            m.extend([f64::from(b), set.len() as f64]);
            m.extend(set.nodes.iter().map(|&k| f64::from(k)));
            set.pack_received(&ks, m);
        }
    });
    out.extend(to);
}

/// The messages of [`pack_solved`]: the bodies whose contacts this rank solves
/// without stepping them get their sender's contact nodes, free velocity and G
/// ([`NodeSet::set_received`]).
pub fn unpack_solved<const D: usize>(stepped: &Stepped, sets: &mut [NodeSet<D>], from: &[(u32, impl AsRef<[f64]>)]) {
    let mut got = vec![false; sets.len()];
    for (_, all) in from {
        let all = all.as_ref();
        let mut i = 0;
        // (body, n, n nodes, v: D n, m, m nodes, their m D rows of D n values) each
        while let (Some(&b), Some(&n)) = (all.get(i), all.get(i + 1)) {
            let (n, nodes) = (n as usize, i + 2);
            let Some(set) = sets.get_mut(b as usize) else { break };
            let nv = D * n;
            let Some(&m) = all.get(nodes + n + nv) else { break };
            let (ks, rows) = (nodes + n + nv + 1, nodes + n + nv + 1 + m as usize);
            let end = rows + m as usize * D * nv;
            if all.len() < end {
                break;
            }
            if stepped.receives(b as usize) {
                let sent: Vec<u32> = all[nodes..nodes + n].iter().map(|&k| k as u32).collect();
                debug_assert!(set.nodes.iter().all(|k| sent.binary_search(k).is_ok()), "body {b}'s contact nodes");
                set.nodes = sent;
                set.set_received(&all[nodes + n..nodes + n + nv], &all[ks..rows], &all[rows..end]);
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

/// The bodies stepped here whose contacts other ranks solve too: their contact
/// nodes, free velocity there and the rows of G asked for, to those ranks
/// ([`pack_solved`]), after the last step's impulses of their contacts at the
/// nodes asked for and on their faces (their warm starts, [`crate::warm`]); the same of the bodies
/// stepped elsewhere whose contacts this rank solves, from their stepping ranks
/// ([`unpack_solved`]). One point-to-point round.
pub fn share_columns<const D: usize>(st: &Stepped, (sets, warm): (&mut [NodeSet<D>], &mut Warm<D>), asked: &Asked, rounds: &dyn Rounds) {
    let mut out = Vec::new();
    pack_solved(st, sets, asked, &mut out);
    let mut to: BTreeMap<u32, Vec<f64>> = out.into_iter().collect();
    if let Some(me) = st.rank_here() {
        let front = rounds_with(st, me, |r, b, m| {
            if st.sends(b as usize) {
                let at = asked.binary_search_by_key(&(b, r), |x| (x.0, x.1));
                let nodes = at.map_or(&[][..], |p| &asked[p].2[..]);
                // (a 3D face candidate's, `1 << 31 |` its face, always: its nodes are
                // not named; the receiver finds what it solves by key)
                warm.pack_body(b, |k| k & 1 << 31 != 0 || nodes.binary_search(&k).is_ok(), m);
            }
        });
        crate::warm::with_front(&mut to, front);
    }
    let from = exchange_with(rounds, to);
    let rest: Vec<(u32, &[f64])> = from
        .iter()
        .map(|(r, m)| {
            let (got, rest) = crate::warm::split_front(m);
            warm.add(got);
            (*r, rest)
        })
        .collect();
    unpack_solved(st, sets, &rest);
}

/// The contacts this rank solves in a step stepped in part ([`Stepped::solved`]),
/// built after the partition with their numbers (W_αα, u_free, targets). The
/// family's contacts are its raw contacts (kept by detection, in key order: their
/// points are the partition's, [`nscdd::dd::Attached::points`]); a rank builds
/// only those it solves, and the impulses of those solved elsewhere stay on
/// their ranks ([`crate::warm`]).
#[derive(Default)]
pub struct Solved<Cs> {
    /// The contacts solved here.
    pub list: Cs,
    /// Their indices among the family's contacts (ascending).
    pub at: Vec<u32>,
    /// Per contact of the family, its index in `list` (`u32::MAX`: solved
    /// elsewhere).
    pub of: Vec<u32>,
    /// What the other ranks asked of the bodies stepped here ([`ask_nodes`]).
    pub asked: Asked,
    /// The other ranks' subdomains, as their ranks describe them
    /// ([`crate::shells::share`]).
    pub shells: Vec<crate::shells::Shell>,
    /// (body, its contact nodes) of the bodies every rank steps, ascending
    /// ([`crate::shells::share`]).
    pub set_lens: Vec<(u32, u32)>,
}

impl<Cs> Solved<Cs> {
    /// The number of contact nodes of body `b` (its entity's values in the
    /// gluing), as the rank stepping it filled its set; `None` if no rank did.
    pub fn set_len(&self, b: u32) -> Option<usize> {
        let at = self.set_lens.binary_search_by_key(&b, |x| x.0).ok()?;
        Some(self.set_lens[at].1 as usize)
    }
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

    /// A build's contacts `c`: the family's list `list` (`own` false: every
    /// contact, one process), or the contacts solved here, one for each of `at`,
    /// among the family's `n` contacts.
    pub fn keep(&mut self, c: Cs, list: &mut Cs, own: bool, n: usize) {
        match own {
            false => *list = c,
            true => {
                self.list = c;
                self.index(n);
            }
        }
    }

    /// Contact `a`'s place in `list` and that list: the contacts solved here
    /// (stepped in part) or the family's `whole` list; `None` if `a` is solved
    /// elsewhere.
    pub fn place<'a>(&'a self, whole: &'a Cs, part: bool, a: usize) -> Option<(&'a Cs, usize)> {
        match part {
            false => Some((whole, a)),
            true => self.of.get(a).filter(|&&l| l != u32::MAX).map(|&l| (&self.list, l as usize)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stepped::AllRanks;

    /// The contacts solved here (the family's 0 and 2 of 3) and their places.
    #[test]
    fn the_contacts_solved_here_and_their_places() {
        let mut sv = Solved::<&str> {
            at: vec![0, 2],
            ..Default::default()
        };
        let mut whole = "whole";
        sv.keep("part", &mut whole, true, 3);
        assert_eq!(sv.of, [0, u32::MAX, 1]);
        assert_eq!(sv.place(&whole, true, 2), Some((&"part", 1)));
        assert_eq!(sv.place(&whole, true, 1), None);
        assert_eq!(sv.place(&whole, false, 1), Some((&"whole", 1)));
        sv.keep("all", &mut whole, false, 3);
        assert_eq!(whole, "all");
    }

    /// A body whose contacts ranks 0 (two) and 1 (one) solve, on 3 ranks: rank 0
    /// steps it; rank 1 asks it for the nodes of its contact, rank 0 sends its
    /// contact nodes, free velocity and those rows of G to rank 1 alone, which
    /// lists rank 0 with an empty message (symmetric), and takes them; rank 2
    /// sends nothing.
    #[test]
    fn a_shared_body_is_stepped_once_and_its_columns_sent() {
        let rank_of = |a: usize| if a < 2 { 0 } else { 1 };
        let rounds = AllRanks::new(3, &rank_of, vec![(0, None); 3]);
        let decide_on = |me: u32| rounds.decide(me, 1);
        let [s0, s1, s2] = [0, 1, 2].map(decide_on);
        assert!(s0.steps(0) && !s1.steps(0) && !s2.steps(0));
        assert!(s0.sends(0) && s1.receives(0) && !s2.receives(0));
        // two contact nodes (4 and 7), rank 1's contact at node 7 only: it asks for
        // it, and only its rows of G are sent; the others read 0 there
        let mut two = NodeSet::<2>::default();
        two.nodes = vec![4, 7];
        two.v = vec![[1.0, 2.0], [3.0, 4.0]];
        two.g = (0..16).map(f64::from).collect();
        // (rank 1's message to rank 0: body 0, one node, node 7)
        let ask = vec![0.0, 1.0, 7.0];
        *rounds.replies.borrow_mut() = vec![ask];
        let asked = ask_nodes(&s0, [(0, 4)].into_iter(), &rounds);
        assert_eq!(asked, [(0, 1, vec![7])]);
        assert!(ask_nodes(&s1, [(0, 7)].into_iter(), &rounds).is_empty());
        assert!(ask_nodes(&s2, std::iter::empty(), &rounds).is_empty());
        let packed = |s: &Stepped, asked: &Asked| {
            let mut out = Vec::new();
            pack_solved(s, std::slice::from_ref(&two), asked, &mut out);
            out
        };
        let (p0, p1, p2) = (packed(&s0, &asked), packed(&s1, &vec![]), packed(&s2, &vec![]));
        // (body 0, 2 nodes: 4 and 7, v, one row node: set index 1, its two rows of G)
        let mut rows: Vec<f64> = vec![0.0, 2.0, 4.0, 7.0, 1.0, 2.0, 3.0, 4.0, 1.0, 1.0];
        rows.extend((8..16).map(f64::from));
        assert_eq!(p0, [(1, rows.clone())]);
        assert_eq!(p1, [(0, vec![])]);
        assert!(p2.is_empty());
        let mut got = vec![NodeSet::<2>::default()];
        got[0].nodes = vec![4, 7];
        unpack_solved(&s1, &mut got, &[(0, rows)]);
        assert_eq!((&got[0].nodes, &got[0].v), (&two.nodes, &two.v));
        assert_eq!(got[0].block(1, 0), two.block(1, 0));
        assert_eq!(got[0].block(1, 1), two.block(1, 1));
        assert_eq!(got[0].block(0, 0), [[0.0; 2]; 2]);
        // rank 0 fails in the step (its body's assembly): it steps nothing, sends
        // nothing of the body and no V⁺ (it steps none: [`crate::near::share`]), but
        // still exchanges with rank 1 (an empty
        // message), whose set then reads no G and zero velocities
        let mut f0 = decide_on(0);
        f0.fail();
        assert!(!f0.steps(0) && !f0.sends(0) && f0.mask() == Some(&[false][..]));
        assert_eq!(packed(&f0, &asked), [(1, vec![])]);
        unpack_solved(&s1, &mut got, &[(0, Vec::<f64>::new())]);
        assert_eq!(got[0].v, [[0.0, 0.0]; 2]);
        assert_eq!(got[0].block(0, 0), [[0.0; 2]; 2]);
    }
}
