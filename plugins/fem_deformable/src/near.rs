//! Which MPI ranks hold a deformable body's boundary current (docs/SCALING.md,
//! "A body's boundary sent where it is near"). A rank that does not step a body
//! reads only its boundary (detection, its contacts, the position update there,
//! [`crate::whole`]), and, detecting in its own cells
//! ([`nscdd::dd::Attached::after_free_velocity_own`]), only for a body whose
//! boundary's box grown by the alert distance meets its cells: a node of another
//! body is then never within the alert distance of it, and none of its nodes is
//! in those cells. So after the sweeps the rank stepping a body sends its V⁺ at
//! its boundary only to the ranks whose cells (of the step's grid: the next
//! detection's) that box meets, at the positions of the next step (u⁺,
//! [`FeBody::u_next`], the position update's arithmetic) ([`share`]); a rank
//! receiving nothing of a body marks it stale, leaves it out of its detection
//! and position update ([`Near::held`]) and drops its state (u, V, V⁻, V_free:
//! [`FeBody::release_state`]; its mesh, material and matrices stay). A rank that
//! held a body stale gets its boundary's u and V⁻ with its V⁺ (its interior left
//! at zero: only the rank stepping a body holds it whole, [`crate::whole`]), so
//! the stepping rank keeps, per body, the
//! ranks holding it current ([`Near`]; handed over with the body's whole state,
//! [`crate::whole::hand_over`]). On a repartition step the last stepping rank
//! sends the boundary (u, V) to the ranks whose new cells the box meets and
//! that lack it, before they detect there ([`new_cells`]). The body's energies
//! after the step and the count of contacts go to rank 0 only (the history's).
//! When the next detection may read every body (no cells given: the
//! centralized scheme, contacts held whole), every rank gets every body.

use crate::body::FeBody;
use crate::stepped::Stepped;
use nscdd::dd::{RankCells, Rounds};
use std::collections::BTreeMap;

/// Which ranks hold each body's boundary current (module docs). Empty: every
/// rank holds every body, as after a load.
#[derive(Default)]
pub struct Near {
    /// Per body: whether this rank holds its boundary current.
    here: Vec<bool>,
    /// Per body whose state this rank holds whole (it stepped it last): the
    /// other ranks holding its boundary current, ascending; `None`: every rank.
    holders: Vec<Option<Vec<u32>>>,
}

impl Near {
    /// Per body, whether this rank holds its boundary current (`None`: every one).
    pub fn held(&self) -> Option<&[bool]> {
        (!self.here.is_empty()).then_some(&self.here[..])
    }

    /// Whether this rank holds body `b`'s boundary current.
    pub fn holds(&self, b: usize) -> bool {
        self.here.get(b).is_none_or(|&h| h)
    }

    /// The other ranks holding body `b`'s boundary current, as its last stepping
    /// rank knows them (`None`: every rank).
    pub fn holders(&self, b: usize) -> Option<&[u32]> {
        self.holders.get(b).and_then(|h| h.as_deref())
    }

    /// Body `b`'s holders ([`Self::holders`]), as the rank handing it over knew
    /// them, on the rank taking it over, with that rank (`from`).
    pub fn take_holders(&mut self, n: usize, b: usize, from: u32, held: Option<Vec<u32>>) {
        self.sized(n);
        self.holders[b] = held.map(|mut h| {
            if let Err(at) = h.binary_search(&from) {
                h.insert(at, from);
            }
            h
        });
        self.here[b] = true;
    }

    fn sized(&mut self, n: usize) {
        if self.here.len() != n {
            self.here = vec![true; n];
            self.holders = vec![None; n];
        }
    }

    fn holds_on(&self, b: usize, q: u32) -> bool {
        self.holders(b).is_none_or(|h| h.binary_search(&q).is_ok())
    }
}

/// The bodies a detection reads ([`Near::held`]; `own`: in this rank's cells).
/// A detection of every body where some are held stale, which the framework
/// never asks (the next detection's cells given to [`share`] are the step's),
/// is a bug: it panics, which stops every rank with the message (the plugin's
/// guard and `MPI_Abort`), since only this rank knows.
pub fn held_for(near: &Near, own: bool) -> Option<&[bool]> {
    let held = near.held();
    assert!(
        own || held.is_none_or(|h| !h.contains(&false)),
        "internal error: a deformable detection of every body, after a step that sent each body only to the ranks near it"
    );
    held
}

/// The ranks whose cells body `b`'s boundary box, at positions `x0 + u(i)`,
/// grown by `alert`, meets, but `me`, ascending, once each.
fn ranks_near(body: &FeBody, u: impl Fn(usize) -> f64, alert: f64, cells: &RankCells<'_>) -> Vec<u32> {
    let d = body.dim();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for &k in &body.mesh.boundary {
        for c in 0..d {
            let i = d * k as usize + c;
            let p = body.mesh.x0[i] + u(i);
            (lo[c], hi[c]) = (lo[c].min(p), hi[c].max(p));
        }
    }
    for c in 0..d {
        (lo[c], hi[c]) = (lo[c] - alert, hi[c] + alert);
    }
    let mut out = Vec::new();
    cells.ranks_meeting(d, &lo[..d], &hi[..d], |q| {
        if q != cells.rank {
            out.push(q);
        }
    });
    out.sort_unstable();
    out.dedup();
    out
}

/// The ranks body `b` goes to after the step (but `me`, ascending): those whose
/// cells (`next`) its box at `u_next` grown by `alert` meets ([`ranks_near`]),
/// every rank without cells, and the ranks that solved its contacts (their
/// residual reads its V⁺).
fn targets(
    st: &Stepped,
    (b, body, u_next): (usize, &FeBody, &[f64]),
    (next, alert): (Option<&RankCells<'_>>, f64),
    (me, ranks): (u32, u32),
) -> Vec<u32> {
    let mut near = match next {
        Some(cells) => ranks_near(body, |i| u_next[i], alert, cells),
        None => (0..ranks).filter(|&q| q != me).collect(),
    };
    let lo = st.solvers().partition_point(|x| x.0 < b as u32);
    let solvers = st.solvers()[lo..].iter().take_while(|x| x.0 == b as u32);
    near.extend(solvers.map(|x| x.1).filter(|&q| q != me));
    near.sort_unstable();
    near.dedup();
    near
}

/// Body `b`'s values at its boundary nodes (`x`: u, V or V⁻).
fn boundary_of(body: &FeBody, x: &[f64], out: &mut Vec<f64>) {
    let d = body.dim();
    out.extend(body.mesh.boundary.iter().flat_map(|&k| &x[d * k as usize..d * k as usize + d]));
}

/// Writes `x` (values at the boundary nodes) into `into` at body's boundary.
fn set_boundary(body_dim: usize, boundary: &[u32], into: &mut [f64], x: &[f64]) {
    for (&k, v) in boundary.iter().zip(x.chunks_exact(body_dim)) {
        into[body_dim * k as usize..body_dim * k as usize + body_dim].copy_from_slice(v);
    }
}

/// After V⁺ of the bodies stepped here: each one's V⁺ at its boundary to the
/// ranks near it (whose cells of the next detection, `next`, its box grown by
/// `alert` meets; every rank without) and to those that solved its contacts, with its u and V⁻ there to those that held it stale;
/// its energies after the step ([`FeBody::energies`] at u⁺) and this rank's
/// count of `contacts` to rank 0 (the history's). Marks the bodies received
/// here, and those stepped here, current ([`Near::held`]).
pub fn share(st: &mut Stepped, bodies: &mut [FeBody], (contacts, alert): (usize, f64), next: Option<&RankCells<'_>>, rounds: &dyn Rounds) {
    let Some((me, ranks)) = st.ranks() else { return };
    let n = bodies.len();
    let (h, theta) = st.ht();
    let mut energy = vec![[f64::NAN; 3]; n];
    let mut to: BTreeMap<u32, Vec<f64>> = BTreeMap::new();
    // (rank 0's header: this rank's contacts, then (body, energies) of its bodies)
    let mut head = vec![contacts as f64, 0.0];
    let mut u_next = Vec::new();
    st.near.sized(n);
    for (b, body) in bodies.iter().enumerate() {
        if !st.steps(b) {
            continue;
        }
        u_next.clear();
        u_next.extend((0..body.u.len()).map(|i| body.u_next(i, h, theta)));
        energy[b] = body.energies(&u_next, &body.v);
        head.push(b as f64);
        head.extend(energy[b]);
        head[1] += 1.0;
        // (a body with a non-finite value goes to every rank, which all stop at
        // this step: [`Stepped::diverged`])
        let bad = !u_next.iter().chain(&body.v).all(|x| x.is_finite());
        let near = targets(st, (b, body, &u_next[..]), (next.filter(|_| !bad), alert), (me, ranks));
        for &q in &near {
            let m = to.entry(q).or_default();
            let stale = !st.near.holds_on(b, q);
            let kind = if bad { 2 } else { u8::from(stale) };
            m.extend([b as f64, f64::from(kind)]);
            if kind != 0 {
                boundary_of(body, &body.u, m);
                boundary_of(body, &body.v_begin, m);
            }
            boundary_of(body, &body.v, m);
        }
        st.near.holders[b] = next.filter(|_| !bad).map(|_| near);
    }
    if me != 0 {
        let rest = to.remove(&0).unwrap_or_default();
        head.extend(rest);
        to.insert(0, head);
    }
    let mut here: Vec<bool> = (0..n).map(|b| st.steps(b)).collect();
    let mut total = contacts;
    for (_, m) in rounds.send(to.into_iter().collect()) {
        let mut rest = &m[..];
        if me == 0 {
            // (the header: the sender's contacts, then (body, energies) of its bodies)
            let (Some(&c), Some(&k)) = (m.first(), m.get(1)) else { continue };
            let Some(es) = m.get(2..2 + 4 * k as usize) else { continue };
            total += c as usize;
            for x in es.chunks_exact(4) {
                if let Some(e) = energy.get_mut(x[0] as usize) {
                    *e = [x[1], x[2], x[3]];
                }
            }
            rest = &m[2 + es.len()..];
        }
        while let (Some(&b), Some(&kind)) = (rest.first(), rest.get(1)) {
            let b = b as usize;
            let Some(body) = bodies.get_mut(b) else { break };
            let (d, nb, stale) = (body.dim(), body.mesh.boundary.len(), kind != 0.0);
            if kind == 2.0 {
                st.diverged.get_or_insert(b as u32);
            }
            let len = d * nb * if stale { 3 } else { 1 };
            let Some(x) = rest.get(2..2 + len) else { break };
            debug_assert!(
                stale || body.u.len() == body.n_dofs(),
                "body {b}'s V⁺ alone, its state not held here"
            );
            body.ensure_state();
            let bd = &body.mesh.boundary;
            if stale {
                set_boundary(d, bd, &mut body.u, &x[..d * nb]);
                set_boundary(d, bd, &mut body.v_begin, &x[d * nb..2 * d * nb]);
            }
            set_boundary(d, bd, &mut body.v, &x[len - d * nb..]);
            here[b] = true;
            rest = &rest[2 + len..];
        }
    }
    // (what a rank holds of a body stale: its mesh, material and matrices)
    for (b, _) in here.iter().enumerate().filter(|x| !*x.1) {
        bodies[b].release_state();
    }
    st.near.here = here;
    st.after_share(energy, total);
}

/// [`nscdd::dd::Attached::new_cells`]: on a repartition step, before detection
/// in the new cells, the rank that stepped a body last (holding it whole) sends
/// its boundary's u and V to the ranks whose new cells its box (grown by
/// `alert`) meets and that hold it stale, which mark it current.
pub fn new_cells(st: &mut Stepped, bodies: &mut [FeBody], alert: f64, cells: &RankCells<'_>, rounds: &dyn Rounds) {
    let n = bodies.len();
    st.near.sized(n);
    let me = cells.rank;
    let mut to: BTreeMap<u32, Vec<f64>> = BTreeMap::new();
    for (b, body) in bodies.iter().enumerate() {
        if st.sender_of(b) != Some(me) || st.near.holders(b).is_none() {
            continue;
        }
        let near = ranks_near(body, |i| body.u[i], alert, cells);
        let Some(held) = st.near.holders[b].as_mut() else { continue };
        for q in near {
            if let Err(at) = held.binary_search(&q) {
                held.insert(at, q);
                let m = to.entry(q).or_default();
                m.push(b as f64);
                boundary_of(body, &body.u, m);
                boundary_of(body, &body.v, m);
            }
        }
    }
    for (_, m) in rounds.send(to.into_iter().collect()) {
        let mut rest = &m[..];
        while let Some(&b) = rest.first() {
            let b = b as usize;
            let Some(body) = bodies.get_mut(b) else { break };
            let (d, nb) = (body.dim(), body.mesh.boundary.len());
            let Some(x) = rest.get(1..1 + 2 * d * nb) else { break };
            body.ensure_state();
            set_boundary(d, &body.mesh.boundary, &mut body.u, &x[..d * nb]);
            set_boundary(d, &body.mesh.boundary, &mut body.v, &x[d * nb..]);
            st.near.here[b] = true;
            rest = &rest[1 + 2 * d * nb..];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stepped::AllRanks;

    /// [`crate::whole::square`] with M = I and K = 2 I (its energies).
    fn square() -> FeBody {
        let b = crate::whole::square();
        let n = b.u.len();
        let eye = |x: f64| crate::python::Csr {
            n,
            indptr: (0..=n).collect(),
            indices: (0..n).collect(),
            data: vec![x; n],
        };
        FeBody::new(None, b.mesh, b.elastic, 0, &eye(1.0), &eye(2.0), String::new()).unwrap()
    }

    /// Ranks 0, 1, 2 hold the slabs x < 1, 1 ≤ x < 2, x ≥ 2 (`shift`: the cuts moved).
    fn slabs(lo: &[f64], hi: &[f64], shift: f64, f: &mut dyn FnMut(u32)) {
        for r in 0..3u32 {
            let (a, b) = (f64::from(r) + shift, f64::from(r) + 1.0 + shift);
            if (r == 0 || hi[0] >= a) && (r == 2 || lo[0] <= b) {
                f(r);
            }
        }
    }

    /// The unit square stepped by rank 0 on three ranks: its V⁺ goes to rank 1
    /// (its box grown by the alert distance meets rank 1's cells, not rank 2's),
    /// rank 2 marks it stale; moved to 1.5 ≤ x ≤ 2.5, rank 2 gets its u and V⁻
    /// with V⁺, rank 1 its V⁺ only; on a repartition, a rank whose new cells it
    /// meets and that holds it stale gets its u and V.
    #[test]
    fn a_body_goes_to_the_ranks_near_it_with_its_state_to_those_holding_it_stale() {
        let rank_of = |_: usize| 0;
        let rounds = AllRanks::new(3, &rank_of, vec![(0, None)]);
        let (mut s0, mut s2) = (rounds.decide(0, 1), rounds.decide(2, 1));
        assert!(s0.steps(0) && !s2.steps(0));
        let meeting = |_: usize, lo: &[f64], hi: &[f64], f: &mut dyn FnMut(u32)| slabs(lo, hi, 0.0, f);
        let cells = |rank| RankCells {
            meeting: &meeting,
            rank,
            ranks: 3,
        };
        let mut bodies = vec![square()];
        bodies[0].v.iter_mut().enumerate().for_each(|(i, v)| *v = i as f64);
        // (V⁻ = V⁺ = v: u⁺ = u + h v, x ≤ 1 + 10⁻³·8)
        bodies[0].v_begin = bodies[0].v.clone();
        share(&mut s0, &mut bodies, (1, 0.1), Some(&cells(0)), &rounds);
        let v_boundary: Vec<f64> = (0..8).map(f64::from).collect();
        let mut rec = vec![0.0, 0.0];
        rec.extend(&v_boundary);
        assert_eq!(rounds.sent.borrow().last().cloned().unwrap(), (vec![1], vec![rec]));
        assert_eq!(s0.near.holders(0), Some(&[1][..]));
        assert_eq!((s0.near.held(), s0.contacts_total()), (Some(&[true][..]), Some(1)));
        let e = s0.energies().unwrap()[0];
        assert!(e[0] > 0.0 && e[1] > 0.0, "{e:?}");
        // rank 2 received nothing of it: stale there, sending rank 0 its header
        let mut at2 = vec![square()];
        share(&mut s2, &mut at2, (0, 0.1), Some(&cells(2)), &rounds);
        assert_eq!(s2.near.held(), Some(&[false][..]));
        assert!(at2[0].u.is_empty() && at2[0].v.is_empty(), "its state dropped there");
        assert_eq!(rounds.sent.borrow().last().cloned().unwrap(), (vec![0], vec![vec![0.0, 0.0]]));
        // moved to 1.5 ≤ x ≤ 2.5: rank 1 holds it, rank 2 gets u and V⁻ too
        (0..5).for_each(|k| bodies[0].u[2 * k] = 1.5);
        share(&mut s0, &mut bodies, (1, 0.1), Some(&cells(0)), &rounds);
        let (peers, msgs) = rounds.sent.borrow().last().cloned().unwrap();
        assert_eq!(peers, [1, 2]);
        assert_eq!(msgs[0][..2], [0.0, 0.0]);
        let u_boundary: Vec<f64> = (0..8).map(|i| if i % 2 == 0 { 1.5 } else { 0.0 }).collect();
        let mut rec = vec![0.0, 1.0];
        rec.extend(u_boundary.iter().chain(&v_boundary).chain(&v_boundary));
        assert_eq!(msgs[1], rec);
        assert_eq!(s0.near.holders(0), Some(&[1, 2][..]));
        // rank 2 takes it: u, V⁻ and V⁺ at the boundary, current again
        *rounds.replies.borrow_mut() = vec![rec];
        share(&mut s2, &mut at2, (0, 0.1), Some(&cells(2)), &rounds);
        assert_eq!(s2.near.held(), Some(&[true][..]));
        assert_eq!(
            (&at2[0].u[..8], &at2[0].v_begin[..8], &at2[0].v[..8]),
            (&u_boundary[..], &v_boundary[..], &v_boundary[..])
        );
        assert_eq!(at2[0].v[8..], [0.0, 0.0], "the interior node is not sent");
        // a repartition: rank 0's new cells are x < 3 (and rank 1's, rank 2's beyond):
        // none new for rank 0's body but rank 0 itself; cuts at 1.5 and 2.5 instead
        let shifted = |_: usize, lo: &[f64], hi: &[f64], f: &mut dyn FnMut(u32)| slabs(lo, hi, 2.6, f);
        let new = RankCells {
            meeting: &shifted,
            rank: 0,
            ranks: 3,
        };
        new_cells(&mut s0, &mut bodies, 0.1, &new, &rounds);
        assert_eq!(rounds.sent.borrow().last().cloned().unwrap(), (vec![], vec![]));
        // back at x ≤ 1 and rank 1 dropped, then the cuts move: rank 1 gets u and V
        (0..5).for_each(|k| bodies[0].u[2 * k] = 0.0);
        s0.near.holders[0] = Some(vec![]);
        let back = |_: usize, lo: &[f64], hi: &[f64], f: &mut dyn FnMut(u32)| slabs(lo, hi, -0.5, f);
        let new = RankCells {
            meeting: &back,
            rank: 0,
            ranks: 3,
        };
        new_cells(&mut s0, &mut bodies, 0.1, &new, &rounds);
        let mut rec = vec![0.0];
        rec.extend(vec![0.0; 8].iter().chain(&v_boundary));
        assert_eq!(rounds.sent.borrow().last().cloned().unwrap(), (vec![1], vec![rec]));
        assert_eq!(s0.near.holders(0), Some(&[1][..]));
    }

    /// A body with a non-finite value (here at its interior node) goes to every
    /// rank whatever the cells, marked so that each stops at this step.
    #[test]
    fn a_diverging_body_goes_to_every_rank_which_stops() {
        let rank_of = |_: usize| 0;
        let rounds = AllRanks::new(3, &rank_of, vec![(0, None)]);
        let (mut s0, mut s2) = (rounds.decide(0, 1), rounds.decide(2, 1));
        let meeting = |_: usize, lo: &[f64], hi: &[f64], f: &mut dyn FnMut(u32)| slabs(lo, hi, 0.0, f);
        let cells = RankCells {
            meeting: &meeting,
            rank: 0,
            ranks: 3,
        };
        let mut bodies = vec![square()];
        bodies[0].v[8] = f64::NAN;
        share(&mut s0, &mut bodies, (1, 0.1), Some(&cells), &rounds);
        let (peers, msgs) = rounds.sent.borrow().last().cloned().unwrap();
        assert_eq!(peers, [1, 2], "every rank, not only rank 1 near it");
        assert_eq!(msgs[1][..2], [0.0, 2.0]);
        assert_eq!(s0.near.holders(0), None);
        *rounds.replies.borrow_mut() = vec![msgs[1].clone()];
        let mut at2 = vec![square()];
        assert_eq!(s2.diverged, None);
        share(&mut s2, &mut at2, (0, 0.1), Some(&cells), &rounds);
        assert_eq!(s2.diverged, Some(0));
    }

    /// Without cells (the next detection reads every body) every rank gets every
    /// body, and stays current.
    #[test]
    fn without_cells_every_rank_gets_every_body() {
        let rank_of = |_: usize| 0;
        let rounds = AllRanks::new(3, &rank_of, vec![(0, None)]);
        let mut s0 = rounds.decide(0, 1);
        let mut bodies = vec![square()];
        share(&mut s0, &mut bodies, (1, 0.1), None, &rounds);
        let (peers, _) = rounds.sent.borrow().last().cloned().unwrap();
        assert_eq!(peers, [1, 2]);
        assert_eq!(s0.near.holders(0), None);
        assert_eq!(held_for(&s0.near, false), Some(&[true][..]));
        s0.near.here[0] = false;
        assert!(std::panic::catch_unwind(|| held_for(&s0.near, false)).is_err());
        assert_eq!(held_for(&s0.near, true), Some(&[false][..]));
    }
}
