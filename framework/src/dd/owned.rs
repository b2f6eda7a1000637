//! Bodies stepped per rank (docs/SCALING.md, "Bodies owned per rank", step 1): with
//! contacts held per rank ([`super::local`]), a rank also steps only the bodies it
//! needs — free velocity, detection boxes and position update — and its world holds
//! only them (compact arrays, [`crate::world::held`]): a body leaves when the rank
//! no longer steps it and enters, with its record, when it comes back.
//!
//! ```text
//! owner(b)   the rank of the grid cell holding b's centre (edge cells unbounded)
//! halo(r)    the bodies whose box, grown by the alert distance, meets r's cells:
//!            every body r's detection can pair (the region's own test)
//! active(r)  halo(r) ∪ the bodies of r's contacts ∪ the fixed, driven, named
//!            and unbounded bodies and those the attached body families touch
//!            (stepped by every rank)
//! reach      the attached families' reach boxes (`Attached::reach`, the same on
//!            every rank): a body whose grown box meets one is in every halo
//! ```
//!
//! A rank steps its active bodies exactly as one process does: their V⁺ is the
//! subdomains' (a rank receives every copy of the bodies it steps) or their free
//! velocity, so an active body's state is bitwise the same on every rank holding it.
//! At the end of a step, the owner of a body at the start of the step sends its new
//! state to the ranks whose halo it has just entered (one all-gather); every rank
//! then keeps the bodies of its new halo. By induction a rank holds every body of its
//! halo at the start of each step. A distributed repartition
//! ([`super::NscddOf::repartition_local`]) sends, in the step, the bodies of each
//! rank's new halo it lacks (their state at the start of the step, V⁻ and V_free);
//! the first step of a fresh run starts from a provisional grid over the bodies'
//! centres ([`Owned::start_held`]), the first step after a restart from the saved
//! grid (a rank's world holds every body, or already only its part when the scene
//! was loaded in part, [`crate::scene::part`]; it then keeps its part).
//!
//! The outputs never read a body its rank does not hold: the sums over bodies are
//! added per cell by the cells' ranks ([`super::census::BodySums`]), the named and
//! driven bodies are stepped by every rank, a body without contacts is written in
//! the VTK frames by its owner, and rank 0 gathers every body's record before it
//! writes `final.json` or a checkpoint ([`super::NscddOf::own_body_records`],
//! merged on rank 0 by [`super::rank_merge`]).

use super::cells::CellIndex;
use super::family::Family;
use super::partition::Grid;
use super::ranks::RankState;
use crate::detect::Region;

/// The state of the mode across steps.
#[derive(Default)]
pub(super) struct Owned {
    /// Every rank's cells at the start of the step (also the boundary-contact
    /// exchange's, [`super::local`]).
    pub cells: Option<CellIndex>,
    /// The active bodies this rank owned at the start of the step.
    mine: Vec<u32>,
    /// Bodies stepped by every rank (fixed, driven, unbounded, and those of
    /// `shared`), by id.
    everywhere: Vec<bool>,
    /// The world bodies the attached families read or touch
    /// ([`super::Attached::held_everywhere`]; ascending): stepped by every rank.
    shared: Vec<u32>,
    /// The next step's bodies, by the world's slot (a buffer).
    keep: Vec<bool>,
    /// The families' reach with which the bodies now held were chosen, and the one
    /// for the next step ([`Owned::set_reach`]).
    reach: Region,
    reach_next: Vec<[[f64; 3]; 2]>,
}

/// The box `b` grown by `alert` ([`Region::grown_box`], the detection's own).
fn grown(n: usize, b: &[[f64; 3]; 2], alert: f64) -> ([f64; 3], [f64; 3]) {
    Region::grown_box(n, &b[0], &b[1], alert)
}

/// The ranks other than `me` whose cells (`after`) a body's box `new`, grown by
/// `alert`, meets and whose cells (`before`) its box `old` did not meet, into `out`
/// (sorted, once each; `was`: scratch).
fn entered(
    n: usize,
    (old, before): (&[[f64; 3]; 2], &CellIndex),
    (new, after): (&[[f64; 3]; 2], &CellIndex),
    alert: f64,
    me: u32,
    (was, out): (&mut Vec<u32>, &mut Vec<u32>),
) {
    (was.clear(), out.clear());
    let (lo, hi) = grown(n, old, alert);
    before.ranks_meeting(n, &lo, &hi, |q| was.push(q));
    let (lo, hi) = grown(n, new, alert);
    after.ranks_meeting(n, &lo, &hi, |q| {
        if q != me && !was.contains(&q) {
            out.push(q);
        }
    });
    out.sort_unstable();
    out.dedup();
}

/// The region of `boxes`.
fn region(boxes: Vec<[[f64; 3]; 2]>) -> Region {
    Region { boxes, pairs: Vec::new() }
}

/// Whether a body's box `new`, grown by `alert`, meets the families' reach `after`
/// and its box `old` did not meet the reach `before` (then only the ranks whose
/// halo holds it have it: its owner sends it to every rank).
fn entered_reach(n: usize, (old, before): (&[[f64; 3]; 2], &Region), (new, after): (&[[f64; 3]; 2], &Region), alert: f64) -> bool {
    if after.boxes.is_empty() {
        return false;
    }
    let (lo, hi) = grown(n, new, alert);
    if !after.meets(n, &lo, &hi) {
        return false;
    }
    let (lo, hi) = grown(n, old, alert);
    !before.meets(n, &lo, &hi)
}

impl Owned {
    /// At the start of a step with contacts held per rank (`boxes`: the active
    /// bodies' boxes): every rank's cells and the bodies this rank owns.
    pub(super) fn start<D: Family>(&mut self, w: &D::World, rs: &RankState, grid: &Grid) {
        self.cells = Some(CellIndex::new(grid, &rs.rank_of));
        let nb = D::n_bodies(w);
        if self.everywhere.len() != nb {
            // and the observed bodies (named or driven: the history reads them on rank 0)
            self.everywhere = (0..nb).map(|g| D::everywhere(w, g)).collect();
            for g in D::observed(w).into_iter().chain(self.shared.iter().copied()) {
                if let Some(e) = self.everywhere.get_mut(g as usize) {
                    *e = true;
                }
            }
        }
        self.own_bodies::<D>(w, rs, grid);
    }

    /// Before the first step of a run or after a restart (every body held, or the
    /// rank's part as loaded; a provisional `grid` over the bodies' centres, or the saved one, and
    /// `rs.rank_of`): the world keeps only this rank's halo, the bodies of its
    /// contacts and the bodies every rank steps, so that the first step too runs
    /// with bodies and contacts per rank.
    pub(super) fn start_held<D: Family>(&mut self, w: &mut D::World, rs: &RankState, grid: &Grid) {
        self.start::<D>(w, rs, grid);
        let mine = Region {
            boxes: super::cells::cells_of(grid, &rs.rank_of, rs.cluster.rank()),
            pairs: Vec::new(),
        };
        let mut boxes = Vec::new();
        self.next_active::<D>(w, &mine, &[], &mut boxes);
    }

    /// The attached families' world bodies (module docs: stepped by every rank),
    /// before the first step.
    pub(super) fn set_shared(&mut self, shared: Vec<u32>) {
        self.shared = shared;
        self.everywhere.clear();
    }

    /// The attached families' reach boxes for the next step (module docs): before
    /// the first step and after each step's write-back.
    pub(super) fn set_reach(&mut self, boxes: Vec<[[f64; 3]; 2]>) {
        self.reach_next = boxes;
    }

    /// The bodies stepped by every rank, by id (set by [`Owned::start`]).
    pub(super) fn everywhere(&self) -> &[bool] {
        &self.everywhere
    }

    /// The active bodies whose centre lies in one of this rank's cells.
    fn own_bodies<D: Family>(&mut self, w: &D::World, rs: &RankState, grid: &Grid) {
        let me = rs.cluster.rank();
        self.mine.clear();
        let owner = |g: usize| rs.rank_of.get(grid.cell_of(D::position(w, g)) as usize) == Some(&me);
        crate::step::each_body(D::n_bodies(w), D::stepped(w), |g| {
            if owner(g) {
                self.mine.push(g as u32);
            }
        });
    }

    /// A distributed repartition in the step (the new `grid` and `rs.rank_of` set,
    /// before the new regions' detection): the bodies of each rank's new halo it
    /// lacks, at the start of the step with their V⁻ and V_free, from their owners
    /// (point to point: each record to the rank it is for); then the new cells and owners. `boxes`:
    /// the active bodies' boxes at the start of the step (the received ones added).
    /// Collective.
    pub(super) fn repartition<D: Family>(
        &mut self,
        w: &mut D::World,
        (rs, grid): (&mut RankState, &Grid),
        boxes: &mut Vec<[[f64; 3]; 2]>,
        v_free: &mut Vec<D::V>,
    ) {
        let alert = D::alert(w);
        let me = rs.cluster.rank();
        let new = CellIndex::new(grid, &rs.rank_of);
        let Some(old) = self.cells.take() else { return };
        // each body's record to the ranks whose new halo it enters, point to point
        // (after the provisional grid of a fresh run's first step, most bodies move)
        let mut out = vec![Vec::new(); rs.cluster.size() as usize];
        let (mut was, mut to) = (Vec::new(), Vec::new());
        for &g in &self.mine {
            let k = D::held_slot(w, g as usize);
            entered(D::SPACE, (&boxes[k], &old), (&boxes[k], &new), alert, me, (&mut was, &mut to));
            for &q in &to {
                let o: &mut Vec<f64> = &mut out[q as usize];
                o.push(f64::from(g));
                D::step_record(w, g as usize, &v_free[k], o);
            }
        }
        let per = 1 + D::STEP_RECORD;
        rs.totals.bodies_sent += out.iter().map(|o| o.len() / per).sum::<usize>() as u64;
        // (the senders in rank order, each in its own: the order of an all-gather)
        let (_, inbox) = rs.send_ranks(out);
        let mut active = D::active(w).map(<[u32]>::to_vec).unwrap_or_default();
        let to_me: Vec<&[f64]> = inbox.iter().flat_map(|b| b.chunks_exact(per)).collect();
        let entering: Vec<(u32, &[f64])> = to_me.iter().map(|x| (x[0] as u32, &x[1..1 + D::BODY_RECORD])).collect();
        // the entering bodies take slots among the held ones: V_free (by slot) follows
        let before: Option<Vec<u32>> = D::held(w).filter(|_| !entering.is_empty()).map(<[u32]>::to_vec);
        D::admit(w, &entering);
        remap::<D>(w, before.as_deref(), v_free);
        for x in to_me {
            let g = x[0] as usize;
            let k = D::held_slot(w, g);
            v_free[k] = D::set_step_record(w, g, &x[1..]);
            active.push(g as u32);
        }
        active.sort_unstable();
        active.dedup();
        D::set_active(w, Some(active));
        D::body_boxes(w, boxes);
        self.cells = Some(new);
        self.own_bodies::<D>(w, rs, grid);
    }

    /// After the position update of a step with contacts held per rank (`boxes`: the
    /// active bodies' boxes at its start; `full_next`: the next step runs with every
    /// body): brings the bodies other ranks now need to them (every owned body to
    /// every rank before a full step), agrees on a divergence, and sets the bodies of
    /// the next step. Collective.
    pub(super) fn after_integrate<D: Family>(
        &mut self,
        w: &mut D::World,
        (rs, grid): (&mut RankState, &Grid),
        (boxes, full_next): (&[[[f64; 3]; 2]], bool),
        moved: Result<(), usize>,
    ) -> Result<(), usize> {
        let alert = D::alert(w);
        let me = rs.cluster.rank() as usize;
        let mut now = Vec::new();
        let (diverged, received) = if D::active(w).is_none() {
            // every rank stepped every body: the same bodies, the same divergence
            (moved.err(), Vec::new())
        } else {
            D::body_boxes(w, &mut now);
            let Some(cells) = self.cells.as_ref() else { return moved };
            let (mut was, mut to) = (Vec::new(), Vec::new());
            let mut entering = |g: u32| {
                let k = D::held_slot(w, g as usize);
                let (new, old) = (&now[k], &boxes[k]);
                entered(D::SPACE, (old, cells), (new, cells), alert, me as u32, (&mut was, &mut to));
                full_next || !to.is_empty()
            };
            let reach = (&self.reach, region(self.reach_next.clone()));
            let mut entering = |g: u32| {
                let k = D::held_slot(w, g as usize);
                entering(g) || entered_reach(D::SPACE, (&boxes[k], reach.0), (&now[k], &reach.1), alert)
            };
            let send: Vec<u32> = self.mine.iter().copied().filter(|&g| entering(g)).collect();
            exchange::<D>(w, rs, &send, moved.err())
        };
        if diverged.is_some() || full_next {
            D::set_active(w, None);
            return diverged.map_or(Ok(()), Err);
        }
        let mine = Region {
            boxes: super::cells::cells_of(grid, &rs.rank_of, me as u32),
            pairs: Vec::new(),
        };
        self.next_active::<D>(w, &mine, &received, &mut now);
        Ok(())
    }

    /// The bodies of the next step: the candidates (the active ones and those just
    /// `received`; all of them after a full step) in this rank's halo (`mine`: its
    /// cells) or contacts, and the bodies every rank steps.
    fn next_active<D: Family>(&mut self, w: &mut D::World, mine: &Region, received: &[u32], boxes: &mut Vec<[[f64; 3]; 2]>) {
        let nb = D::n_bodies(w);
        let alert = D::alert(w);
        // marked by the world's slot (ascending in global id: ≈ N/P flags, not N),
        // a contact's body the world would not hold apart (none expected)
        let mut keep = std::mem::take(&mut self.keep);
        keep.clear();
        keep.resize(D::held(w).map_or(nb, <[u32]>::len), false);
        let mut unheld = Vec::new();
        let c = D::contacts(w);
        for a in 0..D::len(c) {
            for g in D::contact_bodies(w, a) {
                match D::slot(w, g as usize) {
                    Some(k) => keep[k] = true,
                    None => unheld.push(g),
                }
            }
        }
        let candidates: Option<Vec<u32>> = D::active(w).map(|a| {
            let mut v = a.to_vec();
            v.extend_from_slice(received);
            v.sort_unstable();
            v.dedup();
            v
        });
        D::set_active(w, candidates);
        D::body_boxes(w, boxes);
        self.reach = region(std::mem::take(&mut self.reach_next));
        crate::step::each_body(nb, D::stepped(w), |g| {
            let k = D::held_slot(w, g);
            let (lo, hi) = grown(D::SPACE, &boxes[k], alert);
            keep[k] |= self.everywhere[g] || mine.meets(D::SPACE, &lo, &hi) || self.reach.meets(D::SPACE, &lo, &hi);
        });
        let mut active: Vec<u32> = (0..keep.len()).filter(|&k| keep[k]).map(|k| D::global(w, k) as u32).collect();
        if !unheld.is_empty() {
            active.extend(unheld);
            active.sort_unstable();
            active.dedup();
        }
        D::set_active(w, Some(active.clone()));
        // the world holds only them (they come back with their records)
        D::hold(w, &active);
        self.keep = keep;
    }
}

/// `v`, by the slots of `before` (the held ids before bodies entered the world;
/// `None`: every body), moved to the world's slots now (an entering body's value
/// left at its default).
fn remap<D: Family>(w: &D::World, before: Option<&[u32]>, v: &mut Vec<D::V>) {
    let (Some(before), Some(now)) = (before, D::held(w)) else { return };
    if before.len() == now.len() {
        return;
    }
    let mut out = vec![D::V::default(); now.len()];
    for (k, &g) in before.iter().enumerate() {
        out[D::held_slot(w, g as usize)] = v[k];
    }
    *v = out;
}

/// The states of the bodies `send` (and, with `diverged`, of the body found
/// diverging, marked by its id as −1 − id) from every rank to every rank, written
/// into the receivers' worlds (a body one lacks enters it). Returns the first body
/// any rank found diverging and the bodies received. Collective.
pub(super) fn exchange<D: Family>(
    w: &mut D::World,
    rs: &mut RankState,
    send: &[u32],
    diverged: Option<usize>,
) -> (Option<usize>, Vec<u32>) {
    let per = 1 + D::BODY_RECORD;
    let mut mine = Vec::with_capacity((send.len() + 1) * per);
    if let Some(k) = diverged {
        mine.push(-1.0 - k as f64);
        D::body_record(w, k, &mut mine);
    }
    for &g in send {
        mine.push(f64::from(g));
        D::body_record(w, g as usize, &mut mine);
    }
    rs.totals.bodies_sent += send.len() as u64;
    let all = rs.all_gather_any(&mine).1;
    let (mut first, mut got) = (None::<usize>, Vec::new());
    // (the body's id; a diverging one's as −1 − id)
    let id = |x: f64| if x < 0.0 { (-1.0 - x) as u32 } else { x as u32 };
    // a body this process lacks enters with its record
    let entering: Vec<(u32, &[f64])> = all.chunks_exact(per).map(|x| (id(x[0]), &x[1..])).collect();
    D::admit(w, &entering);
    for x in all.chunks_exact(per) {
        let g = id(x[0]) as usize;
        if x[0] < 0.0 {
            first = Some(first.map_or(g, |f| f.min(g)));
        } else {
            got.push(g as u32);
        }
        D::set_body_record(w, g, &x[1..]);
    }
    (first, got)
}
