//! Contact detection, once for 2D and 3D: an O(N) cell-grid broad phase, then the
//! narrow phases that plugins registered for each pair of shape kinds
//! ([`crate::shape::PairDetector`]), called once per batch of candidate pairs.
//!
//! The grid's cell size is the median body extent plus the alert distance, so that
//! a polydisperse sample (radii spread 1:100) keeps few bodies per cell; it grows
//! until the grid has O(N) cells. A bounded body is entered in every cell its box
//! covers, extended by the alert distance towards lower coordinates; a pair whose
//! boxes overlap within the alert distance shares the cell of the lower corner of
//! the intersection of those extended boxes and is reported there only, so no pair
//! appears twice. Bodies whose box spans more than [`LARGE_CELLS`] cells (long
//! walls) and unbounded shapes (half-planes, planes) are kept aside and tested
//! against every body by box overlap. Bodies are bucketed by a counting sort over
//! cells (no hashing). A pair is `[i, j]` with i < j; pairs are sorted by kind pair,
//! then by bodies: the order of the raw contacts depends on the scene only, never
//! on the grid. Pairs of two bodies that impulses cannot move are skipped.
//!
//! A [`Region`] restricts detection to one part of space (a rank's subdomains, once
//! ranks hold only their part: docs/SCALING.md): only the bodies whose box, grown by
//! the alert distance, meets the region enter the broad phase, and a pair is kept
//! when the intersection of its two grown boxes meets the region (or the region
//! names the pair). A contact point lies in both bodies' boxes grown by the alert
//! distance, so every contact whose point is in the region is found; and since pairs
//! are sorted by kind pair and bodies, the result is the whole detection's list
//! restricted to the kept pairs, in the same order.

use crate::dim::{Dim, Vector};
use crate::model::Bodies;
use crate::shape::{Aabb, DetectCtx, PairDetector, RawContact, ShapeStore};
use std::sync::Arc;

/// Bodies spanning more cells than this along one axis are tested against all.
pub const LARGE_CELLS: usize = 8;

/// Detector table resolved at scene load: entry `ka * nk + kb`, with whether the
/// registered order is (kb, ka).
pub struct DetectorTable<D: Dim> {
    pub nk: usize,
    pub table: Vec<Option<(Arc<dyn PairDetector<D>>, bool)>>,
}

impl<D: Dim> Default for DetectorTable<D> {
    fn default() -> Self {
        DetectorTable { nk: 0, table: vec![] }
    }
}

impl<D: Dim> Clone for DetectorTable<D> {
    fn clone(&self) -> Self {
        DetectorTable {
            nk: self.nk,
            table: self.table.clone(),
        }
    }
}

/// Whether the box `[lo, hi]` (first `n` coordinates) meets one of `boxes`
/// (closed boxes, bounds may be infinite).
pub fn boxes_meet(boxes: &[[[f64; 3]; 2]], n: usize, lo: &[f64], hi: &[f64]) -> bool {
    boxes.iter().any(|b| (0..n).all(|k| lo[k] <= b[1][k] && b[0][k] <= hi[k]))
}

/// A part of space for [`Detector::detect`]: a union of axis-aligned boxes (bounds
/// may be infinite; coordinates past the dimension ignored), and pairs of bodies
/// kept wherever they are (sorted, `[i, j]` with i < j).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Region {
    pub boxes: Vec<[[f64; 3]; 2]>,
    pub pairs: Vec<[u32; 2]>,
}

impl Region {
    /// Whether the box `[lo, hi]` (first `n` coordinates) meets one of the boxes.
    pub fn meets(&self, n: usize, lo: &[f64], hi: &[f64]) -> bool {
        boxes_meet(&self.boxes, n, lo, hi)
    }
    /// Whether the intersection of two boxes (`min`, `max`, first `n` coordinates),
    /// each grown by `alert`, meets one of the boxes: the test a pair passes to be
    /// detected in the region (other processes ask it of their own pairs).
    pub fn meets_pair(&self, n: usize, a: (&[f64], &[f64]), b: (&[f64], &[f64]), alert: f64) -> bool {
        let (lo, hi) = Self::pair_box(n, a, b, alert);
        self.meets(n, &lo, &hi)
    }
    /// The box `[min, max]` grown by `alert` (first `n` coordinates, the rest 0): the
    /// box a body's detection in the region tests.
    pub fn grown_box(n: usize, min: &[f64], max: &[f64], alert: f64) -> ([f64; 3], [f64; 3]) {
        let lo: [f64; 3] = std::array::from_fn(|k| if k < n { min[k] - alert } else { 0.0 });
        let hi: [f64; 3] = std::array::from_fn(|k| if k < n { max[k] + alert } else { 0.0 });
        (lo, hi)
    }
    /// The box [`Region::meets_pair`] tests: the intersection of the two boxes, each
    /// grown by `alert`.
    pub fn pair_box(n: usize, a: (&[f64], &[f64]), b: (&[f64], &[f64]), alert: f64) -> ([f64; 3], [f64; 3]) {
        let lo: [f64; 3] = std::array::from_fn(|k| if k < n { a.0[k].max(b.0[k]) - alert } else { 0.0 });
        let hi: [f64; 3] = std::array::from_fn(|k| if k < n { a.1[k].min(b.1[k]) + alert } else { 0.0 });
        (lo, hi)
    }
    fn names(&self, i: u32, j: u32) -> bool {
        self.pairs.binary_search(&[i, j]).is_ok()
    }
}

/// Reusable buffers of the detection stage (no allocation once warmed up).
pub struct Detector<D: Dim> {
    aabb: Vec<Aabb<D>>,
    small: Vec<u32>,
    large: Vec<u32>,
    cell_start: Vec<u32>,
    cell_items: Vec<u32>,
    entries: Vec<(u32, u32)>,
    fill: Vec<u32>,
    pairs: Vec<(u32, [u32; 2])>,
    batch: Vec<[u32; 2]>,
    /// With a region: whether each body enters the broad phase.
    inside: Vec<bool>,
    /// Per small body: the cell of its box's lower corner grown by the alert distance.
    low: Vec<[u32; 3]>,
}

impl<D: Dim> Default for Detector<D> {
    fn default() -> Self {
        Detector {
            aabb: vec![],
            small: vec![],
            large: vec![],
            cell_start: vec![],
            cell_items: vec![],
            entries: vec![],
            fill: vec![],
            pairs: vec![],
            batch: vec![],
            inside: vec![],
            low: vec![],
        }
    }
}

/// The uniform grid over the small bodies' boxes (lower corner `lo`, cell size,
/// cells per axis; axes past D::N have one cell).
struct Grid {
    lo: [f64; 3],
    cell: f64,
    dims: [usize; 3],
}

impl Grid {
    #[inline]
    fn index(&self, x: f64, k: usize) -> usize {
        (((x - self.lo[k]) / self.cell).floor().max(0.0) as usize).min(self.dims[k] - 1)
    }
    #[inline]
    fn flat(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }
    /// The cell of a point (coordinates past `n` ignored).
    #[inline]
    fn cell_of(&self, n: usize, x: impl Fn(usize) -> f64) -> [usize; 3] {
        std::array::from_fn(|k| if k < n { self.index(x(k), k) } else { 0 })
    }
}

impl<D: Dim> Detector<D> {
    /// Runs the broad phase and the narrow phases; fills `out` (cleared first).
    pub fn detect(
        &mut self,
        bodies: &Bodies<D>,
        shapes: &[Box<dyn ShapeStore<D>>],
        table: &DetectorTable<D>,
        alert: f64,
        out: &mut Vec<RawContact<D>>,
    ) {
        self.detect_in(bodies, shapes, table, alert, None, out)
    }

    /// [`Detector::detect`] restricted to `region` (None: everywhere).
    pub fn detect_in(
        &mut self,
        bodies: &Bodies<D>,
        shapes: &[Box<dyn ShapeStore<D>>],
        table: &DetectorTable<D>,
        alert: f64,
        region: Option<&Region>,
        out: &mut Vec<RawContact<D>>,
    ) {
        self.detect_among((bodies, None), shapes, table, alert, region, out)
    }

    /// [`Detector::detect_in`] among the bodies `among.1` only (ascending ids;
    /// `None`: all): the others are not looked at (a process's bodies whose state
    /// it does not hold).
    pub fn detect_among(
        &mut self,
        (bodies, among): (&Bodies<D>, Option<&[u32]>),
        shapes: &[Box<dyn ShapeStore<D>>],
        table: &DetectorTable<D>,
        alert: f64,
        region: Option<&Region>,
        out: &mut Vec<RawContact<D>>,
    ) {
        out.clear();
        let nk = table.nk;
        self.broad_phase((bodies, among), shapes, alert, nk, region);
        let mut p = 0;
        while p < self.pairs.len() {
            let key = self.pairs[p].0;
            let q = p + self.pairs[p..].iter().take_while(|x| x.0 == key).count();
            let (ka, kb) = (key as usize / nk, key as usize % nk);
            if let Some((det, swapped)) = &table.table[key as usize] {
                self.batch.clear();
                self.batch
                    .extend(self.pairs[p..q].iter().map(|x| if *swapped { [x.1[1], x.1[0]] } else { x.1 }));
                let (sa, sb) = if *swapped { (kb, ka) } else { (ka, kb) };
                let ctx = DetectCtx {
                    a: shapes[sa].as_ref(),
                    b: shapes[sb].as_ref(),
                    bodies,
                    alert,
                };
                det.detect(&ctx, &self.batch, out);
            }
            p = q;
        }
    }

    /// Candidate pairs whose boxes overlap within `alert`, sorted by kind pair and
    /// bodies.
    fn broad_phase(
        &mut self,
        (bodies, among): (&Bodies<D>, Option<&[u32]>),
        shapes: &[Box<dyn ShapeStore<D>>],
        alert: f64,
        nk: usize,
        region: Option<&Region>,
    ) {
        self.aabb.clear();
        self.small.clear();
        self.large.clear();
        self.pairs.clear();
        self.boxes((bodies, among), shapes);
        self.mark_inside(region, alert, among);
        let mut cell = self.cell_size(alert);
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for (b, a) in self.aabb.iter().enumerate() {
            if !self.inside[b] {
                continue;
            }
            if !a.is_bounded() || a.extent() > LARGE_CELLS as f64 * cell {
                self.large.push(b as u32);
            } else {
                self.small.push(b as u32);
                for k in 0..D::N {
                    lo[k] = lo[k].min(a.min[k] - alert);
                    hi[k] = hi[k].max(a.max[k]);
                }
            }
        }
        let kind = |b: u32| bodies.shape[b as usize].kind as u32;
        // both bodies movable by impulses or one of them, and the pair in the region
        let wanted = |aabb: &[Aabb<D>], a: u32, b: u32| {
            (bodies.movable(a as usize) || bodies.movable(b as usize))
                && region.is_none_or(|r| {
                    let (x, y) = (&aabb[a as usize], &aabb[b as usize]);
                    let (x, y) = ((x.min.as_ref(), x.max.as_ref()), (y.min.as_ref(), y.max.as_ref()));
                    r.meets_pair(D::N, x, y, alert) || r.names(a.min(b), a.max(b))
                })
        };
        let key = |a: u32, b: u32| kind(a) * nk as u32 + kind(b);
        if !self.small.is_empty() {
            // keep the number of cells O(N)
            let span: [f64; 3] = std::array::from_fn(|k| if k < D::N { (hi[k] - lo[k]).max(cell) } else { cell });
            while span.iter().map(|s| (s / cell).ceil()).product::<f64>() > 4.0 * self.small.len() as f64 + 64.0 {
                cell *= 1.5;
            }
            let dims = std::array::from_fn(|k| ((span[k] / cell).floor() as usize + 1).max(1));
            let grid = Grid { lo, cell, dims };
            self.bucket(&grid, alert);
            for c in 0..self.cell_start.len() - 1 {
                let items = &self.cell_items[self.cell_start[c] as usize..self.cell_start[c + 1] as usize];
                for (p, &a) in items.iter().enumerate() {
                    let ba = &self.aabb[a as usize];
                    for &b in &items[p + 1..] {
                        let bb = &self.aabb[b as usize];
                        if !ba.overlaps(bb, alert) {
                            continue;
                        }
                        // the pair's home cell: that of the lower corner of the extended boxes'
                        // intersection, max(min_a, min_b) − alert; cells are monotone in the
                        // coordinates, so it is the larger of the two bodies' lower cells
                        let (la, lb) = (self.low[a as usize], self.low[b as usize]);
                        let home = std::array::from_fn(|k| la[k].max(lb[k]) as usize);
                        if grid.flat(home) == c && wanted(&self.aabb, a, b) {
                            let (i, j) = if a < b { (a, b) } else { (b, a) };
                            self.pairs.push((key(i, j), [i, j]));
                        }
                    }
                }
            }
        }
        // large bodies against everything
        for (p, &a) in self.large.iter().enumerate() {
            let ba = self.aabb[a as usize];
            for &b in self.small.iter().chain(&self.large[p + 1..]) {
                if ba.overlaps(&self.aabb[b as usize], alert) && wanted(&self.aabb, a, b) {
                    let (i, j) = if a < b { (a, b) } else { (b, a) };
                    self.pairs.push((key(i, j), [i, j]));
                }
            }
        }
        // group by kind pair, then by bodies: a deterministic order
        self.pairs.sort_unstable();
    }

    /// The bodies' boxes; the bodies not `among` get an empty box (never bounded).
    fn boxes(&mut self, (bodies, among): (&Bodies<D>, Option<&[u32]>), shapes: &[Box<dyn ShapeStore<D>>]) {
        let aabb = |b: usize| {
            let s = bodies.shape[b];
            shapes[s.kind as usize].aabb(s.index, bodies.pos[b], bodies.rot[b])
        };
        match among {
            None => self.aabb.extend((0..bodies.len()).map(aabb)),
            Some(list) => {
                let none = Aabb {
                    min: D::Point::from_fn(|_| f64::INFINITY),
                    max: D::Point::from_fn(|_| f64::NEG_INFINITY),
                };
                self.aabb.resize(bodies.len(), none);
                for &b in list {
                    self.aabb[b as usize] = aabb(b as usize);
                }
            }
        }
    }

    /// Which bodies enter the broad phase: all, or those whose box grown by `alert`
    /// meets the region, and the bodies of the pairs it names; only bodies `among`
    /// (ascending; `None`: all).
    fn mark_inside(&mut self, region: Option<&Region>, alert: f64, among: Option<&[u32]>) {
        self.inside.clear();
        let meets = |a: &Aabb<D>| {
            region.is_none_or(|r| {
                let (lo, hi) = Region::grown_box(D::N, a.min.as_ref(), a.max.as_ref(), alert);
                r.meets(D::N, &lo, &hi)
            })
        };
        match among {
            None => self.inside.extend(self.aabb.iter().map(meets)),
            Some(list) => {
                self.inside.resize(self.aabb.len(), false);
                for &b in list {
                    self.inside[b as usize] = meets(&self.aabb[b as usize]);
                }
            }
        }
        let Some(r) = region else { return };
        for p in &r.pairs {
            for &b in p.iter().filter(|b| among.is_none_or(|l| l.binary_search(b).is_ok())) {
                if let Some(x) = self.inside.get_mut(b as usize) {
                    *x = true;
                }
            }
        }
    }

    /// Median extent of the bounded boxes plus the alert distance (1 if none).
    fn cell_size(&self, alert: f64) -> f64 {
        let mut ext: Vec<f64> = self.aabb.iter().filter(|a| a.is_bounded()).map(|a| a.extent()).collect();
        if ext.is_empty() {
            return 1.0;
        }
        let mid = ext.len() / 2;
        ext.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
        let cell = ext[mid] + alert;
        if cell > 0.0 {
            cell
        } else {
            1.0
        }
    }

    /// The small bodies in the cells their extended boxes cover, by a counting sort
    /// over cells (stable: bodies stay in id order inside a cell).
    fn bucket(&mut self, grid: &Grid, alert: f64) {
        self.entries.clear();
        self.low.resize(self.aabb.len(), [0; 3]);
        for &b in &self.small {
            let a = &self.aabb[b as usize];
            let c0 = grid.cell_of(D::N, |k| a.min[k] - alert);
            self.low[b as usize] = c0.map(|x| x as u32);
            let c1 = grid.cell_of(D::N, |k| a.max[k]);
            for z in c0[2]..=c1[2] {
                for y in c0[1]..=c1[1] {
                    for x in c0[0]..=c1[0] {
                        self.entries.push((grid.flat([x, y, z]) as u32, b));
                    }
                }
            }
        }
        let ncell = grid.dims.iter().product::<usize>();
        self.cell_start.clear();
        self.cell_start.resize(ncell + 1, 0);
        for &(c, _) in &self.entries {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..ncell {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        self.cell_items.clear();
        self.cell_items.resize(self.entries.len(), 0);
        self.fill.clear();
        self.fill.extend_from_slice(&self.cell_start);
        for &(c, b) in &self.entries {
            self.cell_items[self.fill[c as usize] as usize] = b;
            self.fill[c as usize] += 1;
        }
    }
}
