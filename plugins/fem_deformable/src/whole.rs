//! The whole state of the deformable bodies on MPI ranks (docs/SCALING.md,
//! "Bodies held at their boundary where not stepped"). In a step stepped in part
//! ([`crate::stepped`]) a rank that does not step a body receives its V⁺ at its
//! boundary nodes only, and only if the body is near its cells
//! ([`crate::near::share`]): detection, the contacts, the reach and the position
//! update there read nothing else of it. Its interior is then stale on that
//! rank, and the rank stepping it is the only one holding it whole. So when a
//! body's stepping rank changes, the last one hands its whole state (u, V) over
//! to the new one ([`hand_over`], point to point, before the free velocities),
//! each rank writes the frame files of the bodies it holds whole
//! ([`crate::stepped::Stepped::writes_frame`]), and before a saved state the
//! ranks send rank 0 the whole state of the bodies they stepped
//! ([`gather_whole`]). After a load every rank holds every body whole.

use crate::body::FeBody;
use crate::nodes::FeKey;
use crate::stepped::Stepped;
use crate::warm::Warm;
use std::collections::BTreeMap;

/// After [`Stepped::decide`] in part: a body whose stepping rank changed gets its
/// whole state (u, V) from the rank that stepped it in the last step (the only
/// one holding it whole since, [`crate::near::share`]), with the last step's
/// impulses of its contacts ([`crate::warm`]) and the ranks holding its boundary
/// current ([`crate::near::Near::holders`]), point to point.
pub fn hand_over<const N: usize>(st: &mut Stepped, bodies: &mut [FeBody], warm: &mut Warm<N>, rounds: &dyn nscdd::dd::Rounds) {
    let Some(me) = st.rank_here() else { return };
    let moved = |b: &usize| st.prev_sender(*b).is_some_and(|p| Some(p) != st.sender_of(*b));
    let (mut to, mut front): (BTreeMap<u32, Vec<f64>>, BTreeMap<u32, Vec<f64>>) = Default::default();
    for b in (0..bodies.len()).filter(moved) {
        let (p, q) = (st.prev_sender(b), st.sender_of(b));
        let (Some(p), Some(q)) = (p, q) else { continue };
        if p == me {
            let m = to.entry(q).or_default();
            m.push(b as f64);
            // (its holders: their count, −1 for every rank)
            let held = st.near.holders(b);
            m.push(held.map_or(-1.0, |h| h.len() as f64));
            m.extend(held.unwrap_or_default().iter().map(|&r| f64::from(r)));
            m.extend(bodies[b].u.iter().chain(&bodies[b].v));
            warm.pack_body(b as u32, |_| true, front.entry(q).or_default());
        } else if q == me {
            to.entry(p).or_default();
        }
    }
    crate::warm::with_front(&mut to, front);
    let n = bodies.len();
    for (from, m) in crate::solved::exchange_with(rounds, to) {
        let (got, mut m) = crate::warm::split_front(&m);
        warm.add(got);
        while let (Some(&b), Some(&k)) = (m.first(), m.get(1)) {
            let (k, len) = (k.max(0.0) as usize, bodies.get(b as usize).map_or(0, |x| 2 * x.n_dofs()));
            let (Some(held), Some(x)) = (m.get(2..2 + k), m.get(2 + k..2 + k + len)) else {
                break;
            };
            if st.sender_of(b as usize) == Some(me) {
                take_whole(bodies, b as usize, x);
                let held = (m[1] >= 0.0).then(|| held.iter().map(|&r| r as u32).collect());
                st.near.take_holders(n, b as usize, from, held);
            }
            m = &m[2 + k + len..];
        }
    }
}

/// [`nscdd::dd::Attached::gather_whole`]: rank 0 gets the whole state (u, V)
/// of the bodies another rank stepped in the last step stepped in part.
pub fn gather_whole(st: &Stepped, bodies: &mut [FeBody], rounds: &dyn nscdd::dd::Rounds) {
    let Some((me, ranks)) = st.ranks() else { return };
    let (peers, out): (Vec<u32>, Vec<Vec<f64>>) = match me {
        0 => ((1..ranks).collect(), vec![Vec::new(); ranks as usize - 1]),
        _ => {
            let mut m = Vec::new();
            for (b, body) in bodies.iter().enumerate().filter(|(b, _)| st.sender_of(*b) == Some(me)) {
                m.push(b as f64);
                m.extend(body.u.iter().chain(&body.v));
            }
            (vec![0], vec![m])
        }
    };
    for m in rounds.exchange(&peers, &out).iter().filter(|_| me == 0) {
        let mut i = 0;
        while let Some(&b) = m.get(i) {
            let len = bodies.get(b as usize).map_or(0, |x| 2 * x.n_dofs());
            let Some(x) = m.get(i + 1..i + 1 + len) else { return };
            take_whole(bodies, b as usize, x);
            i += 1 + len;
        }
    }
}

/// [`nscdd::dd::Attached::gather_whole`]'s contacts: every rank's contacts of the
/// last step (`own`: the contacts it solved, (key, impulse) each) on rank 0, in
/// key order (the saved state's); `None` elsewhere and outside a step stepped in
/// part.
pub fn gather_contacts<const N: usize>(
    st: &Stepped,
    own: impl Iterator<Item = (FeKey, [f64; N])>,
    rounds: &dyn nscdd::dd::Rounds,
) -> Option<Vec<(FeKey, [f64; N])>> {
    let (me, ranks) = st.ranks()?;
    let mine: Vec<(FeKey, [f64; N])> = own.collect();
    let (peers, out): (Vec<u32>, Vec<Vec<f64>>) = match me {
        0 => ((1..ranks).collect(), vec![Vec::new(); ranks as usize - 1]),
        _ => {
            let m = mine
                .iter()
                .flat_map(|(k, r)| [k.0, k.1, k.2, k.3].map(f64::from).into_iter().chain(*r));
            (vec![0], vec![m.collect()])
        }
    };
    let got = rounds.exchange(&peers, &out);
    (me == 0).then(|| {
        let mut all = mine;
        for m in &got {
            all.extend(m.chunks_exact(4 + N).map(|x| {
                let k = (x[0] as u32, x[1] as u32, x[2] as u32, x[3] as u32);
                (k, std::array::from_fn(|q| x[4 + q]))
            }));
        }
        all.sort_unstable_by_key(|x| x.0);
        all
    })
}

/// Body `b`'s whole state (u, V: `x`) into `bodies`.
fn take_whole(bodies: &mut [FeBody], b: usize, x: &[f64]) {
    let Some(body) = bodies.get_mut(b) else { return };
    let n = body.n_dofs();
    if x.len() == 2 * n {
        body.ensure_state();
        body.u.copy_from_slice(&x[..n]);
        body.v.copy_from_slice(&x[n..]);
    }
}

/// A square of four triangles around an interior node (node 4), without M and K
/// (unit tests).
#[cfg(test)]
pub(crate) fn square() -> FeBody {
    let raw = crate::python::RawMesh {
        dim: 2,
        points: vec![0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 0.5, 0.5],
        cells: vec![0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4],
    };
    let el = crate::body::Elastic {
        young: 1e6,
        poisson: 0.3,
        density: 1e3,
        plane_stress: false,
        rayleigh: [0.0; 2],
    };
    FeBody::light(None, crate::mesh::Mesh::new(raw).unwrap(), el, 0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stepped::AllRanks;

    /// A body stepped by rank 0, then by rank 1, seen from rank 1: it takes the
    /// body's V⁺ at its boundary only, then its whole state from rank 0 when it
    /// steps it, and sends that to rank 0 for the outputs; rank 0 sends its whole
    /// state to rank 1 when rank 1 takes it over.
    #[test]
    fn a_body_not_stepped_here_holds_its_boundary_and_is_handed_over_whole() {
        let mut bodies = vec![square()];
        assert_eq!(bodies[0].mesh.boundary, [0, 1, 2, 3]);
        let on_rank = std::cell::Cell::new(0u32);
        let rank_of = |_: usize| on_rank.get();
        let rounds = AllRanks::new(2, &rank_of, vec![(0, None)]);
        let decide = |s: &mut Stepped, me: u32| s.decide(1, Some(&rounds.on(me)), [(0, None)].into_iter(), (1e-3, 0.5));
        let (mut s0, mut s1) = (Stepped::default(), Stepped::default());
        decide(&mut s0, 0);
        decide(&mut s1, 1);
        // the first step after a load: the state is whole everywhere, nothing handed over
        let (mut w0, mut w1) = (Warm::<2>::default(), Warm::<2>::default());
        hand_over(&mut s1, &mut bodies, &mut w1, &rounds);
        assert_eq!(rounds.sent.borrow().last(), Some(&(vec![], vec![])));
        // rank 0's V⁺ at the four boundary nodes (to every rank: no cells given)
        let mut msg = vec![0.0, 0.0];
        msg.extend((1..=8).map(f64::from));
        *rounds.replies.borrow_mut() = vec![msg];
        crate::near::share(&mut s1, &mut bodies, (0, 0.1), None, &rounds);
        assert_eq!(bodies[0].v, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 0.0, 0.0]);
        // (rank 1 steps nothing: rank 0 gets its count of contacts, no energies)
        assert_eq!(rounds.sent.borrow().last(), Some(&(vec![0], vec![vec![0.0, 0.0]])));
        // the contact moves to rank 1: rank 0 sends the whole state, rank 1 takes it
        on_rank.set(1);
        decide(&mut s0, 0);
        decide(&mut s1, 1);
        assert!(!s0.steps(0) && s1.steps(0));
        let whole: Vec<f64> = (0..20).map(f64::from).collect();
        bodies[0].u.copy_from_slice(&whole[..10]);
        bodies[0].v.copy_from_slice(&whole[10..]);
        // (with the last step's impulse of its contact at node 2, [`crate::warm`])
        w0.set([((0, 2, 5, 0), [0.5, 0.25])].into_iter());
        hand_over(&mut s0, &mut bodies, &mut w0, &rounds);
        let mut expect = vec![0.0];
        expect.extend(&whole);
        // (the body, its holders: −1, every rank; its state)
        let mut handed = vec![6.0, 0.0, 2.0, 5.0, 0.0, 0.5, 0.25, 0.0, -1.0];
        handed.extend(&whole);
        assert_eq!(rounds.sent.borrow().last(), Some(&(vec![1], vec![handed.clone()])));
        let mut got = vec![square()];
        *rounds.replies.borrow_mut() = vec![handed];
        hand_over(&mut s1, &mut got, &mut w1, &rounds);
        assert_eq!(rounds.sent.borrow().last(), Some(&(vec![0], vec![vec![0.0]])));
        assert_eq!((&got[0].u[..], &got[0].v[..]), (&whole[..10], &whole[10..]));
        assert_eq!(w1.r_of(&(0, 2, 5, 0)), [0.5, 0.25]);
        // before an output, rank 1 sends the bodies it stepped to rank 0
        gather_whole(&s1, &mut got, &rounds);
        assert_eq!(rounds.sent.borrow().last(), Some(&(vec![0], vec![expect.clone()])));
        let mut at0 = vec![square()];
        *rounds.replies.borrow_mut() = vec![expect];
        gather_whole(&s0, &mut at0, &rounds);
        assert_eq!(rounds.sent.borrow().last(), Some(&(vec![1], vec![vec![]])));
        assert_eq!((&at0[0].u[..], &at0[0].v[..]), (&whole[..10], &whole[10..]));
    }

    /// Every rank's contacts on rank 0, in key order, for the saved state.
    #[test]
    fn every_ranks_contacts_gathered_on_rank_0_in_key_order() {
        let rank_of = |a: usize| u32::from(a == 1);
        let rounds = AllRanks::new(2, &rank_of, vec![(0, None), (1, None)]);
        let (s0, s1) = (rounds.decide(0, 2), rounds.decide(1, 2));
        let at1 = gather_contacts(&s1, [((1, 3, 0, 0), [0.5, 0.25])].into_iter(), &rounds);
        assert_eq!(at1, None);
        let sent = rounds.sent.borrow().last().cloned().unwrap();
        assert_eq!(sent, (vec![0], vec![vec![1.0, 3.0, 0.0, 0.0, 0.5, 0.25]]));
        *rounds.replies.borrow_mut() = sent.1;
        let own0 = [((2, 0, 0, 0), [1.0, 0.0]), ((0, 7, 0, 0), [2.0, 0.0])];
        let at0 = gather_contacts(&s0, own0.into_iter(), &rounds).unwrap();
        let keys: Vec<FeKey> = at0.iter().map(|x| x.0).collect();
        assert_eq!(keys, [(0, 7, 0, 0), (1, 3, 0, 0), (2, 0, 0, 0)]);
        assert_eq!(at0[1].1, [0.5, 0.25]);
        // outside a step stepped in part: nothing gathered
        assert_eq!(gather_contacts::<2>(&Stepped::default(), std::iter::empty(), &rounds), None);
    }
}
