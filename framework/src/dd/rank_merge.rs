//! Rank 0's merge of every rank's records, ascending by key, a bounded number at a
//! time: how `final.json` and the checkpoints get the bodies and contacts that other
//! ranks hold without rank 0 holding all of them at once.
//!
//! Each rank gives its records (`rec` values each, ascending by their first `key`
//! values, integers below 2⁵³: body ids, contact keys). The ranks first learn every
//! rank's count (one all-gather for all the merges of an output, [`RankState::merges`]).
//! Then rank 0 pulls ([`Merge::next`]): a round is one all-gather of rank 0's
//! requests (which ranks send, or the end of the merge) and one gather of the
//! requested ranks' next records, at most [`per_round`] from each; rank 0 asks a
//! rank again only when it has merged every record it had from it. So rank 0 holds
//! at most ranks × [`per_round`] records (≈ 1 MiB), whatever the sample's size, and
//! the others call [`Merge::serve`], which answers the rounds until the end. Rank 0
//! ends each merge ([`Merge::finish`]) even when its writing failed half way, so that
//! no rank waits for a round that never comes.

use super::ranks::RankState;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::Instant;

/// Records pulled one at a time, ascending by key: `pull(out)` puts the next one
/// in `out`, false at the end (on rank 0, [`Merge::next`]).
pub type Pull<'a> = &'a mut dyn FnMut(&mut Vec<f64>) -> bool;

/// The values rank 0 holds for one merge at most (per round, over every rank).
const BUDGET_VALUES: usize = 1 << 17;

/// The records a rank sends per round: [`BUDGET_VALUES`] / (ranks × `rec`), at
/// least one; `NSCDD_MERGE_RECORDS` sets it (tests: many rounds on a small scene).
pub fn per_round(ranks: usize, rec: usize) -> usize {
    match std::env::var("NSCDD_MERGE_RECORDS").ok().and_then(|v| v.parse::<usize>().ok()) {
        Some(n) if n > 0 => n,
        _ => (BUDGET_VALUES / (ranks.max(1) * rec.max(1))).max(1),
    }
}

/// One merge of an output, on every rank: this rank's records, every rank's count
/// left to send, and on rank 0 what it received and has not merged yet.
pub struct Merge {
    rec: usize,
    key: usize,
    per_round: usize,
    /// This rank's records, and how many it has sent.
    mine: Vec<f64>,
    sent: usize,
    /// Records each rank has not sent yet (the same on every rank).
    left: Vec<usize>,
    /// Rank 0: per rank, its last round's records and the next one to merge.
    buf: Vec<Vec<f64>>,
    pos: Vec<usize>,
    heads: BinaryHeap<Reverse<([u64; 3], u32)>>,
    started: bool,
    stopped: bool,
}

impl RankState {
    /// The merges of one output (collective: every rank gives its `M` inputs, each
    /// `(records, rec, key)`, in the same order): one all-gather of every rank's
    /// counts.
    pub fn merges<const M: usize>(&mut self, inputs: [(Vec<f64>, usize, usize); M]) -> [Merge; M] {
        let counts: Vec<f64> = inputs.iter().map(|(v, rec, _)| (v.len() / (*rec).max(1)) as f64).collect();
        let (_, all) = self.all_gather_any(&counts);
        let p = self.cluster.size() as usize;
        let mut i = 0;
        inputs.map(|(mine, rec, key)| {
            i += 1;
            Merge {
                rec,
                key: key.min(3),
                per_round: per_round(p, rec),
                mine,
                sent: 0,
                left: (0..p).map(|r| all[r * M + i - 1] as usize).collect(),
                buf: vec![Vec::new(); p],
                pos: vec![0; p],
                heads: BinaryHeap::new(),
                started: false,
                stopped: false,
            }
        })
    }
}

impl Merge {
    /// Rank 0: the next record of every rank's, ascending by key, into `out`; false
    /// (and the merge ended for every rank) once every record is merged.
    pub fn next(&mut self, rs: &mut RankState, out: &mut Vec<f64>) -> bool {
        if self.stopped {
            return false;
        }
        if !self.started {
            self.started = true;
            let want: Vec<bool> = self.left.iter().map(|&n| n > 0).collect();
            self.round(rs, &want, false);
            for r in 0..self.buf.len() {
                self.push_head(r);
            }
        }
        let Some(Reverse((_, r))) = self.heads.pop() else {
            self.finish(rs);
            return false;
        };
        let r = r as usize;
        let at = self.pos[r];
        out.clear();
        out.extend_from_slice(&self.buf[r][at..at + self.rec]);
        self.pos[r] += self.rec;
        if self.pos[r] == self.buf[r].len() && self.left[r] > 0 {
            let want: Vec<bool> = (0..self.left.len()).map(|q| q == r).collect();
            self.round(rs, &want, false);
        }
        self.push_head(r);
        true
    }

    /// Rank 0: ends the merge for every rank (once; [`Merge::next`] ends it itself
    /// after the last record).
    pub fn finish(&mut self, rs: &mut RankState) {
        if !self.stopped {
            self.round(rs, &[], true);
        }
    }

    /// The other ranks: answers rank 0's rounds until it ends the merge.
    pub fn serve(&mut self, rs: &mut RankState) {
        while !self.stopped {
            self.round(rs, &[], false);
        }
    }

    /// Rank r's next unmerged record's key, among the heads.
    fn push_head(&mut self, r: usize) {
        let (b, at) = (&self.buf[r], self.pos[r]);
        if at < b.len() {
            let mut k = [0u64; 3];
            for (q, x) in k.iter_mut().zip(&b[at..at + self.key]) {
                *q = *x as u64;
            }
            self.heads.push(Reverse((k, r as u32)));
        }
    }

    /// One round (collective): rank 0's requests (`want`, or `stop`) to every rank,
    /// then the requested records to rank 0.
    fn round(&mut self, rs: &mut RankState, want: &[bool], stop: bool) {
        let t0 = Instant::now();
        let (p, me) = (self.left.len(), rs.cluster.rank() as usize);
        let mut ask = Vec::new();
        if me == 0 {
            ask.push(if stop { 1.0 } else { 0.0 });
            ask.extend((0..p).map(|r| if want.get(r) == Some(&true) { 1.0 } else { 0.0 }));
        }
        let mut flags = Vec::new();
        let mut counts = vec![0; p];
        counts[0] = p + 1;
        rs.cluster.all_gather(&ask, &counts, &mut flags);
        if me == 0 {
            // rank 0's requests to every other rank
            rs.totals.reduce.messages += p as u64 - 1;
            rs.totals.reduce.values += (p as u64 - 1) * (p as u64 + 1);
        }
        if flags[0] != 0.0 {
            self.stopped = true;
            rs.totals.reduce_seconds += t0.elapsed().as_secs_f64();
            return;
        }
        let n: Vec<usize> = (0..p)
            .map(|r| if flags[1 + r] != 0.0 { self.per_round.min(self.left[r]) } else { 0 })
            .collect();
        let counts: Vec<usize> = n.iter().map(|k| k * self.rec).collect();
        let mine = &self.mine[self.sent * self.rec..(self.sent + n[me]) * self.rec];
        self.sent += n[me];
        let mut all = Vec::new();
        rs.cluster.gather(mine, &counts, &mut all);
        // a requested rank's records to rank 0
        if me != 0 && !mine.is_empty() {
            rs.totals.reduce.messages += 1;
            rs.totals.reduce.values += mine.len() as u64;
        }
        if me == 0 {
            let mut at = 0;
            for r in (0..p).filter(|&r| n[r] > 0) {
                self.buf[r].clear();
                self.buf[r].extend_from_slice(&all[at..at + counts[r]]);
                self.pos[r] = 0;
                at += counts[r];
            }
        }
        for (l, k) in self.left.iter_mut().zip(&n) {
            *l -= k;
        }
        rs.totals.reduce_seconds += t0.elapsed().as_secs_f64();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dd::cluster::Solo;

    #[test]
    fn one_rank_merges_its_records_in_rounds() {
        let mut rs = RankState::new(Box::new(Solo));
        // records of 2 values, key 1: ids 1, 4, 9
        let recs = vec![1.0, 10.0, 4.0, 40.0, 9.0, 90.0];
        let mut m = rs.merges([(recs, 2, 1), (vec![], 3, 3)]);
        m[0].per_round = 2;
        let mut out = vec![];
        let mut got = vec![];
        while m[0].next(&mut rs, &mut out) {
            got.extend_from_slice(&out);
        }
        assert_eq!(got, [1.0, 10.0, 4.0, 40.0, 9.0, 90.0]);
        assert!(!m[1].next(&mut rs, &mut out), "an empty merge ends at once");
        m[1].finish(&mut rs);
    }
}
