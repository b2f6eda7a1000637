//! 3D contact detection: a broad phase on a uniform grid of cells (bounded shapes)
//! plus an all-pairs test of unbounded or very large ones (planes, walls), then the
//! plugins' narrow phases called once per batch of candidate pairs of the same pair
//! of shape kinds.
//!
//! Each bounded body is entered in the cells its box covers, extended by the alert
//! distance towards lower coordinates; a pair whose boxes overlap within the alert
//! distance shares the cell of the lower corner of the intersection of those extended
//! boxes, and is tested there only, so that no pair is produced twice and no sort
//! is needed. Pairs are produced in a deterministic order (cells in index order,
//! bodies in id order inside a cell).

use crate::registry3::{Aabb3, DetectCtx3, PairDetector3, RawContact3, ShapeStore3};
use crate::rigid3d::Bodies3;
use std::sync::Arc;

/// Detector per pair of kind ids: `table[ka * nk + kb]`, with whether the
/// registered order is (kb, ka).
#[derive(Clone, Default)]
pub struct DetectorTable3 {
    pub nk: usize,
    pub table: Vec<Option<(Arc<dyn PairDetector3>, bool)>>,
}

/// Bounded boxes larger than this many cells are treated as large.
const LARGE_CELLS: f64 = 8.0;

/// Reusable buffers (no allocation once warmed up).
#[derive(Default)]
pub struct Detector3 {
    aabb: Vec<Aabb3>,
    small: Vec<u32>,
    large: Vec<u32>,
    cell_start: Vec<u32>,
    cell_items: Vec<u32>,
    entries: Vec<(u32, u32)>,
    fill: Vec<u32>,
    pairs: Vec<(u32, [u32; 2])>,
    batch: Vec<[u32; 2]>,
}

impl Detector3 {
    /// Raw contacts of all pairs within `alert`, in a deterministic order.
    pub fn detect(
        &mut self,
        bodies: &Bodies3,
        shapes: &[Box<dyn ShapeStore3>],
        table: &DetectorTable3,
        alert: f64,
        out: &mut Vec<RawContact3>,
    ) {
        out.clear();
        let nk = table.nk;
        self.broad_phase(bodies, shapes, alert, nk);
        // stable sort by kind pair keeps the deterministic order inside a batch
        self.pairs.sort_by_key(|p| p.0);
        let mut p = 0;
        while p < self.pairs.len() {
            let key = self.pairs[p].0;
            let q = p + self.pairs[p..].iter().take_while(|x| x.0 == key).count();
            let (ka, kb) = (key as usize / nk, key as usize % nk);
            if let Some((det, swapped)) = &table.table[ka * nk + kb] {
                self.batch.clear();
                self.batch
                    .extend(self.pairs[p..q].iter().map(|x| if *swapped { [x.1[1], x.1[0]] } else { x.1 }));
                let (sa, sb) = if *swapped { (kb, ka) } else { (ka, kb) };
                let ctx = DetectCtx3 {
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

    fn broad_phase(&mut self, bodies: &Bodies3, shapes: &[Box<dyn ShapeStore3>], alert: f64, nk: usize) {
        let n = bodies.len();
        self.aabb.clear();
        self.small.clear();
        self.large.clear();
        self.pairs.clear();
        for b in 0..n {
            let s = bodies.shape[b];
            self.aabb.push(shapes[s.kind as usize].aabb(s.index, bodies.pos[b], bodies.rot[b]));
        }
        let mut ext: Vec<f64> = self.aabb.iter().filter(|a| a.is_bounded()).map(|a| a.extent()).collect();
        let mut cell = 1.0;
        if !ext.is_empty() {
            let mid = ext.len() / 2;
            ext.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
            cell = ext[mid] + alert;
            if !(cell > 0.0) {
                cell = 1.0;
            }
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for (b, a) in self.aabb.iter().enumerate() {
            if !a.is_bounded() || a.extent() > LARGE_CELLS * cell {
                self.large.push(b as u32);
            } else {
                self.small.push(b as u32);
                for k in 0..3 {
                    lo[k] = lo[k].min(a.min[k] - alert);
                    hi[k] = hi[k].max(a.max[k]);
                }
            }
        }
        let kind = |b: u32| bodies.shape[b as usize].kind as u32;
        let movable = |b: u32| bodies.movable(b as usize);
        let key = |a: u32, b: u32| kind(a) * nk as u32 + kind(b);
        if !self.small.is_empty() {
            let span = [(hi[0] - lo[0]).max(cell), (hi[1] - lo[1]).max(cell), (hi[2] - lo[2]).max(cell)];
            while (span[0] / cell).ceil() * (span[1] / cell).ceil() * (span[2] / cell).ceil() > 4.0 * self.small.len() as f64 + 64.0 {
                cell *= 1.5;
            }
            let dims: [usize; 3] = std::array::from_fn(|k| ((span[k] / cell).floor() as usize + 1).max(1));
            let cidx = |x: f64, k: usize| (((x - lo[k]) / cell).floor().max(0.0) as usize).min(dims[k] - 1);
            let flat = |c: [usize; 3]| (c[2] * dims[1] + c[1]) * dims[0] + c[0];
            self.entries.clear();
            for &b in &self.small {
                let a = &self.aabb[b as usize];
                let c0: [usize; 3] = std::array::from_fn(|k| cidx(a.min[k] - alert, k));
                let c1: [usize; 3] = std::array::from_fn(|k| cidx(a.max[k], k));
                for z in c0[2]..=c1[2] {
                    for y in c0[1]..=c1[1] {
                        for x in c0[0]..=c1[0] {
                            self.entries.push((flat([x, y, z]) as u32, b));
                        }
                    }
                }
            }
            let ncell = dims[0] * dims[1] * dims[2];
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
            for c in 0..ncell {
                let items = &self.cell_items[self.cell_start[c] as usize..self.cell_start[c + 1] as usize];
                for (p, &a) in items.iter().enumerate() {
                    let ba = &self.aabb[a as usize];
                    for &b in &items[p + 1..] {
                        let bb = &self.aabb[b as usize];
                        if !(movable(a) || movable(b)) || !ba.overlaps(bb, alert) {
                            continue;
                        }
                        // the pair's home cell: lower corner of the extended boxes' intersection
                        let home: [usize; 3] = std::array::from_fn(|k| cidx(ba.min[k].max(bb.min[k]) - alert, k));
                        if flat(home) != c {
                            continue;
                        }
                        let (i, j) = if a < b { (a, b) } else { (b, a) };
                        self.pairs.push((key(i, j), [i, j]));
                    }
                }
            }
        }
        // large bodies against everything
        for (p, &a) in self.large.iter().enumerate() {
            let ba = self.aabb[a as usize];
            for &b in self.small.iter().chain(&self.large[p + 1..]) {
                if !(movable(a) || movable(b)) || !ba.overlaps(&self.aabb[b as usize], alert) {
                    continue;
                }
                let (i, j) = if a < b { (a, b) } else { (b, a) };
                self.pairs.push((key(i, j), [i, j]));
            }
        }
    }
}
