//! The other ranks' subdomains as shells (contacts held per rank, [`super::local`]):
//! their bodies only, so that a rank's multiplicities, chains and F_Γ are those of
//! one process; and the counts over shared bodies that the outputs read.
//!
//! ```text
//! limited shells  subdomain t's rank sends body b of t to rank R (point to point,
//!                 RankState::send_ranks) when
//!                   b is stepped by every rank (fixed, driven, named, unbounded), or
//!                   b's box grown by the alert distance meets R's cells, or
//!                   R announced b (one small all-gather): a body R steps or holds
//!                   that the box test misses (a kept contact drifted off R's cells)
//! a repartition   the same rule, over the new cells, carries each copy of the last
//!                 step's subdomains with its kept F_Γ from its old rank: the store
//!                 of the bodies near R, and their last subdomains (the migrations)
//! whole shells    every subdomain's body list to every rank (two all-gathers), with
//!                 the centralized scheme or while a rank steps every body
//! ```
//!
//! Every rank holding b tests the same box (b's state is bitwise the same wherever
//! it is stepped), so R receives either every copy of b or none: every body R steps
//! or holds in its subdomains comes with all its copies, and R's interface is the
//! one-process interface restricted to those bodies. What reads more than that is
//! reduced over the ranks: the history's interface counts and whether any body is
//! fresh ([`interface_totals`]), the migrations ([`migrations`]: counted by the rank
//! of a body's first subdomain), the census' loaded contacts of shared bodies and
//! the bodies' subdomains of the VTK frames ([`copy_counts`], asked of the copies'
//! ranks), a fresh body's kept F_Γ ([`super::rank_fresh`]). A shell's local ids
//! are this rank's; [`super::Subdomain::remote_id`] gives its rank's. With limited
//! shells the step before a repartition ends by requests as any other
//! ([`super::rank_share`]): the repartition step routes the kept F_Γ instead of
//! every subdomain's results going to every rank.

use super::cells::CellIndex;
use super::family::Family;
use super::partition::{Decomposition, FGammaStore};
use super::ranks::RankState;
use super::subdomain::Subdomain;
use crate::detect::Region;

/// What decides which bodies of its subdomains a rank sends to another (module docs).
pub(super) struct Near<'a> {
    /// Every rank's cells.
    pub cells: &'a CellIndex,
    /// The bodies' boxes at the start of the step, by slot (those a rank steps up
    /// to date), and the slot of a held body.
    pub boxes: &'a [[[f64; 3]; 2]],
    pub slot: Box<dyn Fn(u32) -> usize + 'a>,
    /// Bodies stepped by every rank, by id.
    pub everywhere: &'a [bool],
    /// The bodies this rank steps (ascending).
    pub active: &'a [u32],
    pub alert: f64,
    /// (body, rank) of the bodies each rank announced ([`RankState::announce`]).
    pub asked: &'a [(u32, u32)],
}

impl Near<'_> {
    /// Whether body g's grown box meets rank r's cells.
    fn meets<D: Family>(&self, g: u32, r: u32) -> bool {
        let mut any = false;
        self.ranks_of::<D>(g, |q| any |= q == r);
        any
    }

    /// Calls `f` with the ranks whose cells body g's grown box meets.
    fn ranks_of<D: Family>(&self, g: u32, f: impl FnMut(u32)) {
        let b = &self.boxes[(self.slot)(g)];
        let (lo, hi) = Region::grown_box(D::SPACE, &b[0], &b[1], self.alert);
        self.cells.ranks_meeting(D::SPACE, &lo, &hi, f);
    }

    /// The ranks (`np` of them) that may need body g, into `to` (ascending, once each).
    fn targets<D: Family>(&self, g: u32, np: usize, to: &mut Vec<u32>) {
        to.clear();
        if self.everywhere[g as usize] {
            return to.extend(0..np as u32);
        }
        self.ranks_of::<D>(g, |q| to.push(q));
        to.extend(of_body(self.asked, g).iter().map(|e| e.1));
        to.sort_unstable();
        to.dedup();
    }
}

impl RankState {
    /// The other ranks' subdomains' bodies, in their order (two all-gathers): whole
    /// shells ([`super::partition::decompose_owned`]).
    pub(super) fn fill_shells<D: Family>(&mut self, subs: &mut [Subdomain<D>]) {
        let ns = subs.len();
        let lens = self.per_subdomain(ns, 1, |s, out| out.push(subs[s].body_global.len() as f64));
        let (at, all) = self.per_subdomain_v(
            ns,
            |s| lens[s] as usize,
            |s, out| out.extend(subs[s].body_global.iter().map(|&g| f64::from(g))),
        );
        for (s, sub) in subs.iter_mut().enumerate() {
            if !self.is_own(s as u32) {
                sub.body_global = all[at[s]..at[s] + lens[s] as usize].iter().map(|&g| g as u32).collect();
                self.totals.shell_bodies += lens[s] as u64;
            }
        }
    }

    /// The bodies this rank steps (`near.active`) or holds (`held`: its contacts'
    /// bodies) that the box test misses, announced to every rank (one all-gather):
    /// (body, rank) of every rank's, sorted ([`Near::asked`]). Collective.
    pub(super) fn announce<D: Family>(&mut self, near: &Near, held: impl Iterator<Item = u32>) -> Vec<(u32, u32)> {
        let me = self.cluster.rank();
        // each body tested once (a contact's bodies come with each of its contacts)
        let mut extra: Vec<u32> = near.active.iter().copied().chain(held).collect();
        extra.sort_unstable();
        extra.dedup();
        extra.retain(|&g| !near.everywhere[g as usize] && !near.meets::<D>(g, me));
        let mine: Vec<f64> = extra.iter().map(|&g| f64::from(g)).collect();
        let (counts, all) = self.all_gather_any(&mine);
        let mut asked: Vec<(u32, u32)> = Vec::with_capacity(all.len());
        let mut start = 0;
        for (q, &n) in counts.iter().enumerate() {
            asked.extend(all[start..start + n].iter().map(|&g| (g as u32, q as u32)));
            start += n;
        }
        asked.sort_unstable();
        asked
    }

    /// The other ranks' subdomains limited to the bodies this rank may need, from
    /// their ranks point to point (module docs; the attached families' copies
    /// come after their split, [`Self::route_family_copies`]). Collective.
    pub(super) fn fill_shells_near<D: Family>(&mut self, subs: &mut [Subdomain<D>], near: &Near) {
        // each own subdomain's bodies (subdomain, local id, body) to the ranks that may need them
        let own: Vec<&Subdomain<D>> = subs.iter().filter(|s| self.is_own(s.id)).collect();
        let (got, _) = self.route(own.into_iter(), near, (false, &|_| 0), |s, l, g, o| {
            o.extend([f64::from(s.id), l as f64, f64::from(g)]);
        });
        for sub in subs.iter_mut().filter(|s| !self.is_own(s.id)) {
            sub.body_global.clear();
            sub.shell_local.clear();
            sub.limited_shell = true;
        }
        // a rank's subdomains in ascending id, each in its local order
        for x in got.iter().flat_map(|m| m.chunks_exact(3)) {
            let sub = &mut subs[x[0] as usize];
            sub.body_global.push(x[2] as u32);
            sub.shell_local.push(x[1] as u32);
        }
        self.totals.shell_bodies += got.iter().map(|m| m.len() as u64 / 3).sum::<u64>();
        self.totals.limited_shells += 1;
    }

    /// After the attached families' split: their copies of this rank's subdomains
    /// (those past `first[s]`) to the ranks that may need their bodies, by the rule
    /// of [`Self::fill_shells_near`], point to point. A copy a family made into a
    /// limited shell here gets its id on the subdomain's rank; one it did not
    /// make (its family copies only what this rank holds) is added. Returns the
    /// copies added (body, subdomain, local id). So a rank needs no family to copy
    /// the same bodies in the same order as the subdomain's rank. Collective.
    pub(super) fn route_family_copies<D: Family>(&mut self, subs: &mut [Subdomain<D>], near: &Near, first: &[u32]) -> Vec<(u32, u32, u32)> {
        let own: Vec<&Subdomain<D>> = subs.iter().filter(|s| self.is_own(s.id)).collect();
        let from = |s: &Subdomain<D>| first.get(s.id as usize).map_or(0, |&f| f as usize);
        let (got, _) = self.route(own.into_iter(), near, (false, &from), |s, l, g, o| {
            o.extend([f64::from(s.id), l as f64, f64::from(g)]);
        });
        // (another rank's limited shells only: its messages name no other; each
        // family copy there by (subdomain, body))
        let limited = |s: &Subdomain<D>| s.limited_shell && s.shell_local.len() == s.body_global.len();
        let mut at: std::collections::HashMap<(u32, u32), usize> = Default::default();
        for s in subs.iter().filter(|s| limited(s)) {
            let f = from(s).min(s.body_global.len());
            at.extend((f..s.body_global.len()).map(|k| ((s.id, s.body_global[k]), k)));
        }
        let mut added = Vec::new();
        for x in got.iter().flat_map(|m| m.chunks_exact(3)) {
            let (s, l, g) = (x[0] as u32, x[1] as u32, x[2] as u32);
            let Some(sub) = subs.get_mut(s as usize).filter(|sub| limited(sub)) else {
                continue;
            };
            match at.get(&(s, g)) {
                Some(&k) => sub.shell_local[k] = l,
                None => {
                    added.push((g, s, sub.body_global.len() as u32));
                    sub.body_global.push(g);
                    sub.shell_local.push(l);
                }
            }
        }
        self.totals.shell_bodies += added.len() as u64;
        debug_assert!(
            subs.iter().all(|s| !s.shell_local.contains(&u32::MAX)),
            "a family copied into a limited shell a body its subdomain's rank did not route here"
        );
        added
    }

    /// Each copy of `subs` (this rank's subdomains; from local id `from(s)` on) to
    /// the ranks that may need its body ([`Near::targets`]), as `pack(subdomain,
    /// local id, body, out)` appends it, point to point; returns what the other
    /// ranks sent this one and, with `to_me`, this rank's own part. Collective.
    fn route<'s, D: Family>(
        &mut self,
        subs: impl Iterator<Item = &'s Subdomain<D>>,
        near: &Near,
        (to_me, from): (bool, &dyn Fn(&Subdomain<D>) -> usize),
        mut pack: impl FnMut(&Subdomain<D>, usize, u32, &mut Vec<f64>),
    ) -> (Vec<Vec<f64>>, Vec<f64>) {
        let (me, np) = (self.cluster.rank(), self.cluster.size() as usize);
        let mut out: Vec<Vec<f64>> = vec![Vec::new(); np];
        let mut to: Vec<u32> = Vec::new();
        for s in subs {
            for (l, &g) in s.body_global.iter().enumerate().skip(from(s)) {
                near.targets::<D>(g, np, &mut to);
                for &q in to.iter().filter(|&&q| to_me || q != me) {
                    pack(s, l, g, &mut out[q as usize]);
                }
            }
        }
        let mine = std::mem::take(&mut out[me as usize]);
        let (_, got) = self.send_ranks(out);
        (got, mine)
    }

    /// On a repartition step with limited shells (the new cells and ranks set,
    /// before the partition): each copy of the last step's own subdomains
    /// (`last`, its ranks `old_rank_of`) goes, with its kept F_Γ, to the ranks that
    /// may need its body now. Returns the store of the bodies near this rank (every
    /// copy's kept F_Γ: those of one process) and their last subdomains, (body,
    /// subdomain) sorted: the migrations' "before". Collective.
    pub(super) fn route_repartition<D: Family>(
        &mut self,
        last: &Decomposition<D>,
        store: &FGammaStore<D::V>,
        near: &Near,
    ) -> (FGammaStore<D::V>, Vec<(u32, u32)>) {
        let me = self.cluster.rank();
        let old_rank_of = std::mem::take(&mut self.old_rank_of);
        let old_own = last.subs.iter().filter(|s| old_rank_of.get(s.id as usize) == Some(&me));
        let (got, mine) = self.route(old_own, near, (true, &|_| 0), |s, _, g, o| {
            let kept = store.get(g, s.id);
            o.extend([f64::from(s.id), f64::from(g), f64::from(u8::from(kept.is_some()))]);
            o.extend_from_slice(kept.unwrap_or_default().as_ref());
        });
        // (subdomain, body, whether it kept an F_Γ, F_Γ)
        let per = 3 + super::subdomain::dofs::<D>();
        let (mut entries, mut before) = (Vec::new(), Vec::new());
        for x in got.iter().chain([&mine]).flat_map(|m| m.chunks_exact(per)) {
            let (t, g) = (x[0] as u32, x[1] as u32);
            before.push((g, t));
            if x[2] > 0.0 {
                let mut v = D::V::default();
                v.as_mut().copy_from_slice(&x[3..]);
                entries.push((g, t, v));
            }
        }
        before.sort_unstable();
        (FGammaStore::from_entries(entries), before)
    }
}

/// The bodies whose subdomains changed at a repartition: held by some subdomain
/// both in `before` (the last step's copies, [`super::partition::copies`]) and now,
/// by other subdomains. With `ranks` (limited shells, `before` routed: one
/// all-gather) each rank counts the bodies whose first subdomain is its own (it
/// knows all their copies, old and new) and the counts are added. Collective with
/// `ranks`.
pub(super) fn migrations<D: Family>(mut ranks: Option<&mut RankState>, d: &Decomposition<D>, before: &[(u32, u32)]) -> usize {
    let after = super::partition::copies(d);
    let mut n = 0usize;
    let mut i = 0;
    while i < after.len() {
        let (g, first) = after[i];
        let now = of_body(&after[i..], g);
        let was = of_body(before, g);
        if ranks.as_ref().is_none_or(|rs| rs.is_own(first)) {
            n += usize::from(!was.is_empty() && was != now);
        }
        i += now.len();
    }
    match ranks.as_mut() {
        Some(rs) => rs.all_sum(&[n as f64])[0] as usize,
        None => n,
    }
}

/// The pairs of body `g` in `pairs`, sorted by body.
fn of_body(pairs: &[(u32, u32)], g: u32) -> &[(u32, u32)] {
    let a = pairs.partition_point(|e| e.0 < g);
    let n = pairs[a..].iter().take_while(|e| e.0 == g).count();
    &pairs[a..a + n]
}

impl<D: Family> super::NscddOf<D> {
    /// Before the partition, with contacts held per rank: whether this step's shells
    /// are limited (the decentralized scheme, while this rank steps some bodies
    /// only: `self.local.limited`); if so the bodies every rank announced and, on a
    /// repartition step, the store routed from the last step's ranks (module docs;
    /// it replaces this rank's) and the migrations' "before". Collective.
    pub(super) fn start_shells(&mut self, w: &D::World, repart: bool) -> Option<(Vec<(u32, u32)>, Option<Vec<(u32, u32)>>)> {
        let decentralized = self.settings.scheme == super::Scheme::Decentralized;
        let limited = self.local.now && decentralized && near_of::<D>(&self.local, w, &[]).is_some();
        // a step after limited shells is limited too (the same scheme and mode, and
        // every rank steps some bodies only): its repartition routes the kept F_Γ
        // that the step before did not share
        debug_assert!(!self.local.limited || limited, "limited shells lost between two steps");
        self.local.limited = limited;
        if !limited {
            return None;
        }
        let (rs, near) = (self.ranks.as_mut()?, near_of::<D>(&self.local, w, &[])?);
        let c = D::contacts(w);
        let asked = rs.announce::<D>(&near, (0..D::len(c)).flat_map(|a| D::contact_bodies(w, a)));
        let near = Near { asked: &asked, ..near };
        // (a restart's whole store needs no routing: [`super::local`])
        let before = (repart && !self.local.whole_store).then(|| {
            let (store, before) = rs.route_repartition(&self.last, &self.store, &near);
            self.store = store;
            before
        });
        drop(near);
        Some((asked, before))
    }
}

/// The rule of a step's limited shells ([`Near`]; None while this rank steps every
/// body).
pub(super) fn near_of<'a, D: Family>(local: &'a super::local::Local, w: &'a D::World, asked: &'a [(u32, u32)]) -> Option<Near<'a>> {
    Some(Near {
        cells: local.owned.cells.as_ref()?,
        boxes: &local.boxes,
        slot: Box::new(move |g| D::held_slot(w, g as usize)),
        everywhere: local.owned.everywhere(),
        active: D::active(w)?,
        alert: D::alert(w),
        asked,
    })
}

/// A step's totals over the ranks (contacts held per rank).
pub(super) struct Totals {
    pub contacts: usize,
    /// The interface bodies and links, the largest multiplicity, and whether some
    /// interface body is fresh: those of one process.
    pub bodies: usize,
    pub links: usize,
    pub max_multiplicity: u32,
    pub fresh: bool,
}

/// The step's totals from every rank's share (one all-gather; `contacts`: this
/// rank's): each rank counts the interface bodies and links whose first copy is in
/// its subdomains, the largest multiplicity of its subdomains' bodies, and whether
/// one of its copies is fresh (it knows every copy of those bodies). Collective.
pub(super) fn interface_totals<D: Family>(rs: &mut RankState, d: &Decomposition<D>, contacts: usize) -> Totals {
    let ifc = &d.iface;
    let own = |s: u32| rs.is_own(s);
    let (mut bodies, mut links, mut fresh) = (0usize, 0usize, false);
    for ib in 0..ifc.len() {
        let ks = ifc.copies(ib);
        if own(ifc.sub[ks.start]) {
            bodies += 1;
            links += ks.len() - 1;
        }
        fresh |= ifc.fresh[ib] && ks.clone().any(|k| own(ifc.sub[k]));
    }
    let m = d.subs.iter().filter(|s| own(s.id));
    let max = m.flat_map(|s| s.copy_mult.iter().copied()).max().unwrap_or(0);
    let mine = [
        contacts as f64,
        bodies as f64,
        links as f64,
        f64::from(max),
        f64::from(u8::from(fresh)),
    ];
    let (_, all) = rs.all_gather_any(&mine);
    let x = all.chunks_exact(mine.len());
    Totals {
        contacts: x.clone().map(|x| x[0] as usize).sum(),
        bodies: x.clone().map(|x| x[1] as usize).sum(),
        links: x.clone().map(|x| x[2] as usize).sum(),
        max_multiplicity: x.clone().map(|x| x[3] as u32).max().unwrap_or(0),
        fresh: x.clone().any(|x| x[4] > 0.0),
    }
}

/// Every copy (body, subdomain, count) of the bodies held by several subdomains and
/// by one of this rank's, sorted, where `counts[s]` (given for this rank's
/// subdomains, by local body) are the subdomains' per-copy counts; the other ranks'
/// asked of their ranks (collective; in one process every subdomain is its own).
pub(super) fn copy_counts<D: Family>(
    d: &Decomposition<D>,
    ranks: Option<&mut RankState>,
    counts: &[Option<Vec<u32>>],
) -> Vec<(u32, u32, u32)> {
    let own = |s: usize| counts[s].is_some();
    let mut out = Vec::new();
    for (s, sub) in d.subs.iter().enumerate().filter(|(s, _)| own(*s)) {
        let c = counts[s].as_deref().unwrap_or_default();
        for (l, &g) in sub.body_global.iter().enumerate() {
            if sub.copy_mult[l] >= 2 {
                out.push((g, s as u32, c[l]));
            }
        }
    }
    if let Some(rs) = ranks {
        // those bodies (ascending: no flag per scene body), and the other ranks'
        // copies of them: (subdomain, their local id)
        let mut held: Vec<u32> = out.iter().map(|x| x.0).collect();
        held.sort_unstable();
        held.dedup();
        let (mut asks, mut bodies) = (Vec::new(), Vec::new());
        for (s, sub) in d.subs.iter().enumerate().filter(|(s, _)| !own(*s)) {
            for (l, &g) in sub.body_global.iter().enumerate() {
                // (a copy no route named: none, [`RankState::route_family_copies`])
                if held.binary_search(&g).is_ok() && sub.remote_id(l as u32) != u32::MAX {
                    asks.push((s as u32, sub.remote_id(l as u32)));
                    bodies.push(g);
                }
            }
        }
        let got = rs.ask_ranks(&asks, 1, |s, l, v| {
            v.push(counts[s as usize].as_ref().map_or(0.0, |c| f64::from(c[l as usize])));
        });
        out.extend(asks.iter().zip(&bodies).zip(&got).map(|((a, &g), &n)| (g, a.0, n as u32)));
    }
    out.sort_unstable();
    out
}

/// The subdomain owning most of each body's contacts (ties: the smaller id; −1
/// without contacts), as `NscddOf::view` counts them over the whole contact list:
/// exact for the bodies of this rank's subdomains and the bodies it owns (another
/// holder's id for the other bodies it knows, −1 for the rest; the VTK pieces read
/// no others, `Piece::has_body`): a
/// body held by one subdomain is its; the counts of the bodies held by several
/// come from their subdomains' ranks (collective).
pub(super) fn body_subdomains<D: Family>(rs: &mut RankState, d: &Decomposition<D>, nb: usize) -> Vec<i32> {
    let counts: Vec<Option<Vec<u32>>> = d
        .subs
        .iter()
        .map(|sub| {
            rs.is_own(sub.id).then(|| {
                let mut n = vec![0u32; sub.body_global.len()];
                for a in 0..D::len(&sub.contacts) {
                    for l in D::bodies(&sub.contacts, a) {
                        n[l as usize] += 1;
                    }
                }
                n
            })
        })
        .collect();
    let copies = copy_counts(d, Some(rs), &counts);
    let mut out = vec![-1i32; nb];
    for sub in d.subs.iter().rev() {
        for &g in &sub.body_global {
            out[g as usize] = sub.id as i32;
        }
    }
    let mut best = vec![0u32; nb];
    // ascending subdomain ids: a strictly larger count wins
    for (g, s, n) in copies {
        if n > best[g as usize] {
            best[g as usize] = n;
            out[g as usize] = s as i32;
        }
    }
    out
}
