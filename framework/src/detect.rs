//! Contact detection: an O(N) cell-grid broad phase, then the narrow phases that
//! plugins registered for each pair of shape kinds.
//!
//! The grid's cell size is the median body extent plus the alert distance, so that
//! a polydisperse sample (radii spread 1:100) keeps few bodies per cell. A body is
//! inserted in every cell its box covers; a pair is reported only by the cell holding
//! the lower corner of the two boxes' intersection, so each pair appears once. Bodies
//! whose box spans more than [`LARGE_CELLS`] cells (long walls) and unbounded shapes
//! (half-planes) are kept aside and tested against every body by box overlap. The
//! bodies are bucketed by a counting sort over cells: no hashing, deterministic order.
//! Pairs of two bodies that impulses cannot move are skipped.

use crate::registry::{Aabb2, PairDetector2, RawContact2, ShapeStore2};
use crate::rigid2d::Bodies2;
use std::sync::Arc;

/// Bodies spanning more cells than this along one axis are tested against all.
pub const LARGE_CELLS: usize = 8;

/// Detector table resolved at scene load: entry `ka * nk + kb`.
#[derive(Clone, Default)]
pub struct DetectorTable {
    pub nk: usize,
    pub table: Vec<Option<(Arc<dyn PairDetector2>, bool)>>,
}

/// Reusable buffers of the detection stage (no allocation once warmed up).
#[derive(Default)]
pub struct Detector {
    aabb: Vec<Aabb2>,
    small: Vec<u32>,
    large: Vec<u32>,
    cell_start: Vec<u32>,
    cell_items: Vec<u32>,
    entries: Vec<(u32, u32)>,
    pairs: Vec<(u32, [u32; 2])>,
    batch: Vec<[u32; 2]>,
}

impl Detector {
    /// Candidate pairs whose boxes overlap within `alert`, grouped by kind pair.
    fn broad_phase(&mut self, bodies: &Bodies2, shapes: &[Box<dyn ShapeStore2>], alert: f64, nk: usize) {
        let n = bodies.len();
        self.aabb.clear();
        self.small.clear();
        self.large.clear();
        self.pairs.clear();
        for b in 0..n {
            let s = bodies.shape[b];
            self.aabb.push(shapes[s.kind as usize].aabb(s.index, bodies.pos[b], bodies.rot[b]));
        }
        let mut ext: Vec<f64> = self
            .aabb
            .iter()
            .filter(|a| a.is_bounded())
            .map(|a| (a.max[0] - a.min[0]).max(a.max[1] - a.min[1]))
            .collect();
        let mut cell = 1.0;
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        if !ext.is_empty() {
            let mid = ext.len() / 2;
            ext.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
            cell = ext[mid] + alert;
            if !(cell > 0.0) {
                cell = 1.0;
            }
        }
        for (b, a) in self.aabb.iter().enumerate() {
            let big = !a.is_bounded() || (a.max[0] - a.min[0]).max(a.max[1] - a.min[1]) > LARGE_CELLS as f64 * cell;
            if big {
                self.large.push(b as u32);
            } else {
                self.small.push(b as u32);
                for k in 0..2 {
                    lo[k] = lo[k].min(a.min[k]);
                    hi[k] = hi[k].max(a.max[k]);
                }
            }
        }
        let movable = |b: u32| bodies.movable(b as usize);
        let kind = |b: u32| bodies.shape[b as usize].kind as u32;
        let key = |a: u32, b: u32| kind(a) * nk as u32 + kind(b);
        if !self.small.is_empty() {
            // keep the number of cells O(N)
            let span = [(hi[0] - lo[0]).max(cell), (hi[1] - lo[1]).max(cell)];
            while (span[0] / cell).ceil() * (span[1] / cell).ceil() > 4.0 * self.small.len() as f64 + 16.0 {
                cell *= 1.5;
            }
            let nx = ((span[0] / cell).floor() as usize + 1).max(1);
            let ny = ((span[1] / cell).floor() as usize + 1).max(1);
            let cidx = |x: f64, k: usize, m: usize| (((x - lo[k]) / cell).floor().max(0.0) as usize).min(m - 1);
            self.entries.clear();
            for &b in &self.small {
                let a = &self.aabb[b as usize];
                let (x0, x1) = (cidx(a.min[0] - alert, 0, nx), cidx(a.max[0], 0, nx));
                let (y0, y1) = (cidx(a.min[1] - alert, 1, ny), cidx(a.max[1], 1, ny));
                for iy in y0..=y1 {
                    for ix in x0..=x1 {
                        self.entries.push(((iy * nx + ix) as u32, b));
                    }
                }
            }
            // counting sort by cell (stable: bodies stay in id order inside a cell)
            let ncell = nx * ny;
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
            let mut fill = self.cell_start.clone();
            for &(c, b) in &self.entries {
                self.cell_items[fill[c as usize] as usize] = b;
                fill[c as usize] += 1;
            }
            for c in 0..ncell {
                let items = &self.cell_items[self.cell_start[c] as usize..self.cell_start[c + 1] as usize];
                let (cx, cy) = (c % nx, c / nx);
                for (p, &a) in items.iter().enumerate() {
                    let ba = &self.aabb[a as usize];
                    for &b in &items[p + 1..] {
                        let bb = &self.aabb[b as usize];
                        if !ba.overlaps(bb, alert) || !(movable(a) || movable(b)) {
                            continue;
                        }
                        // report only in the cell of the lower corner of the overlap
                        let ox = cidx(ba.min[0].max(bb.min[0]) - alert, 0, nx);
                        let oy = cidx(ba.min[1].max(bb.min[1]) - alert, 1, ny);
                        if ox == cx && oy == cy {
                            self.pairs.push((key(a, b), [a, b]));
                        }
                    }
                }
            }
        }
        for (p, &a) in self.large.iter().enumerate() {
            let ba = self.aabb[a as usize];
            for &b in self.small.iter().chain(&self.large[p + 1..]) {
                if (movable(a) || movable(b)) && ba.overlaps(&self.aabb[b as usize], alert) {
                    self.pairs.push((key(a, b), [a, b]));
                }
            }
        }
        // group by kind pair, then by bodies: a deterministic order
        self.pairs.sort_unstable();
    }

    /// Runs the broad phase and the narrow phases; fills `out` (cleared first).
    pub fn detect(
        &mut self,
        bodies: &Bodies2,
        shapes: &[Box<dyn ShapeStore2>],
        table: &DetectorTable,
        alert: f64,
        out: &mut Vec<RawContact2>,
    ) {
        out.clear();
        let nk = table.nk;
        self.broad_phase(bodies, shapes, alert, nk);
        let mut k = 0;
        while k < self.pairs.len() {
            let key = self.pairs[k].0;
            let mut e = k;
            while e < self.pairs.len() && self.pairs[e].0 == key {
                e += 1;
            }
            let (ka, kb) = ((key as usize) / nk, (key as usize) % nk);
            if let Some((det, swapped)) = &table.table[key as usize] {
                self.batch.clear();
                if *swapped {
                    self.batch.extend(self.pairs[k..e].iter().map(|(_, [a, b])| [*b, *a]));
                } else {
                    self.batch.extend(self.pairs[k..e].iter().map(|(_, p)| *p));
                }
                let (sa, sb) = if *swapped { (kb, ka) } else { (ka, kb) };
                let ctx = crate::registry::DetectCtx {
                    a: shapes[sa].as_ref(),
                    b: shapes[sb].as_ref(),
                    bodies,
                    alert,
                };
                det.detect(&ctx, &self.batch, out);
            }
            k = e;
        }
    }
}
