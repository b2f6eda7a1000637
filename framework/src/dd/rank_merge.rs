//! Rank 0's merge of every rank's records, ascending by key, a bounded number at a
//! time: how `final.json` and the checkpoints get the bodies and contacts that other
//! ranks hold without rank 0 holding all of them at once.
//!
//! Each rank gives its records (`rec` values each, ascending by their first `key`
//! values, integers below 2⁵³: body ids, contact keys) to the merges of an output,
//! in the order the file is written ([`RankState::merges`]: one all-gather of every
//! rank's counts; a merge of no records at all is over at once, on every rank).
//! Then rank 0 pulls ([`Merges::pull`]): a round is one all-gather of rank 0's
//! requests (the merge, and how many records each rank sends, or the merge's end)
//! and one gather of the requested records; rank 0 asks a rank again only when it
//! has merged every record it had from it, at most [`per_round`] at a time. So rank
//! 0 holds at most ranks × [`per_round`] records (≈ 1 MiB, up to 1024 records a
//! rank past 128 / `rec` ranks: ≈ 8 in 3D) whatever the sample's size. The other
//! ranks call [`Merges::serve`], which answers the rounds of each merge in turn
//! until rank 0 ends it. Pulling a merge
//! ends the earlier ones, and [`Merges::finish`] ends every merge, also when rank
//! 0's writing failed half way: no rank waits for a round that never comes. A
//! rank's answer follows rank 0's request alone (not its own environment).

use super::ranks::RankState;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::Instant;

/// Records pulled one at a time, ascending by key: `pull(out)` puts the next one
/// in `out`, false at the end (on rank 0, [`Merges::pull`]).
pub type Pull<'a> = &'a mut dyn FnMut(&mut Vec<f64>) -> bool;

/// The values rank 0 asks of all the ranks together in a round, at most (past
/// [`MIN_RECORDS`] a rank).
const BUDGET_VALUES: usize = 1 << 17;
/// The records rank 0 asks of a rank at least (so that the rounds stay few on many
/// ranks).
const MIN_RECORDS: usize = 1024;

/// The records rank 0 asks of a rank in a round: [`BUDGET_VALUES`] / (ranks ×
/// `rec`), at least [`MIN_RECORDS`]; `NSCDD_MERGE_RECORDS` on rank 0 sets it (tests:
/// many rounds on a small scene).
pub fn per_round(ranks: usize, rec: usize) -> usize {
    match std::env::var("NSCDD_MERGE_RECORDS").ok().and_then(|v| v.parse::<usize>().ok()) {
        Some(n) if n > 0 => n,
        _ => (BUDGET_VALUES / (ranks.max(1) * rec.max(1))).max(MIN_RECORDS),
    }
}

/// One merge of an output, on every rank: this rank's records and how many it has
/// sent, and on rank 0 every rank's count left and what it received and has not
/// merged yet.
struct Merge {
    rec: usize,
    key: usize,
    per_round: usize,
    mine: Vec<f64>,
    sent: usize,
    left: Vec<usize>,
    buf: Vec<Vec<f64>>,
    pos: Vec<usize>,
    heads: BinaryHeap<Reverse<([u64; 3], u32)>>,
    /// The gather's buffer, reused.
    all: Vec<f64>,
    started: bool,
    stopped: bool,
}

/// The merges of one output, in the order rank 0 writes them.
pub struct Merges {
    list: Vec<Merge>,
}

impl RankState {
    /// The merges of one output (collective: every rank gives the same number of
    /// inputs, each `(records, rec, key)`, in the order the file is written): one
    /// all-gather of every rank's counts.
    pub fn merges(&mut self, inputs: Vec<(Vec<f64>, usize, usize)>) -> Merges {
        let counts: Vec<f64> = inputs.iter().map(|(v, rec, _)| (v.len() / (*rec).max(1)) as f64).collect();
        let (_, all) = self.all_gather_any(&counts);
        let (m, p) = (inputs.len(), self.cluster.size() as usize);
        // (every rank gives the same number of merges)
        debug_assert_eq!(all.len(), p * m);
        let list = inputs
            .into_iter()
            .enumerate()
            .map(|(i, (mine, rec, key))| {
                let left: Vec<usize> = (0..p).map(|r| all[r * m + i] as usize).collect();
                Merge {
                    rec: rec.max(1),
                    key: key.clamp(1, 3).min(rec.max(1)),
                    per_round: per_round(p, rec),
                    mine,
                    sent: 0,
                    // no records on any rank: over at once, on every rank
                    stopped: left.iter().all(|&n| n == 0),
                    left,
                    buf: vec![Vec::new(); p],
                    pos: vec![0; p],
                    heads: BinaryHeap::new(),
                    all: Vec::new(),
                    started: false,
                }
            })
            .collect();
        Merges { list }
    }
}

impl Merges {
    /// Rank 0: the next record of merge `i`, ascending by key over every rank's,
    /// into `out`; false (and the merge ended for every rank) once every record is
    /// merged. The merges before `i` are ended first.
    pub fn pull(&mut self, i: usize, rs: &mut RankState, out: &mut Vec<f64>) -> bool {
        for (k, m) in self.list.iter_mut().enumerate().take(i) {
            m.finish(rs, k);
        }
        self.list.get_mut(i).is_some_and(|m| m.next(rs, i, out))
    }

    /// Rank 0: ends every merge for every rank, in order (each once); whether every
    /// record of every merge was pulled (false: the file misses some; its writer
    /// stopped early, or left a merge out).
    pub fn finish(&mut self, rs: &mut RankState) -> bool {
        let whole = self.list.iter().all(|m| m.left.iter().all(|&n| n == 0) && m.heads.is_empty());
        for (k, m) in self.list.iter_mut().enumerate() {
            m.finish(rs, k);
        }
        whole
    }

    /// The other ranks: answers rank 0's rounds of each merge in turn until rank 0
    /// ends it.
    pub fn serve(&mut self, rs: &mut RankState) {
        for (k, m) in self.list.iter_mut().enumerate() {
            while !m.stopped {
                m.round(rs, k, None);
            }
        }
    }
}

impl Merge {
    /// Rank 0: the next record, ascending by key.
    fn next(&mut self, rs: &mut RankState, id: usize, out: &mut Vec<f64>) -> bool {
        if self.stopped {
            return false;
        }
        if !self.started {
            self.started = true;
            let want: Vec<bool> = self.left.iter().map(|&n| n > 0).collect();
            self.round(rs, id, Some(&want));
            for r in 0..self.buf.len() {
                self.push_head(r);
            }
        }
        let Some(Reverse((_, r))) = self.heads.pop() else {
            self.finish(rs, id);
            return false;
        };
        let r = r as usize;
        let at = self.pos[r];
        out.clear();
        out.extend_from_slice(&self.buf[r][at..at + self.rec]);
        self.pos[r] += self.rec;
        if self.pos[r] == self.buf[r].len() && self.left[r] > 0 {
            let want: Vec<bool> = (0..self.left.len()).map(|q| q == r).collect();
            self.round(rs, id, Some(&want));
        }
        self.push_head(r);
        true
    }

    /// Rank 0: ends the merge for every rank (once).
    fn finish(&mut self, rs: &mut RankState, id: usize) {
        if !self.stopped {
            self.round(rs, id, Some(&[]));
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

    /// One round (collective): rank 0's request (`want`: the ranks it asks, none
    /// to end the merge; `None` on the other ranks), then the requested records to
    /// rank 0. Request: [merge `id`, end, records asked of each rank].
    fn round(&mut self, rs: &mut RankState, id: usize, want: Option<&[bool]>) {
        let t0 = Instant::now();
        let (p, me) = (rs.cluster.size() as usize, rs.cluster.rank() as usize);
        let mut ask = Vec::new();
        if let Some(want) = want {
            let end = !want.iter().any(|&w| w);
            ask.extend([id as f64, if end { 1.0 } else { 0.0 }]);
            ask.extend((0..p).map(|r| {
                if want.get(r) == Some(&true) {
                    self.per_round.min(self.left[r]) as f64
                } else {
                    0.0
                }
            }));
        }
        let mut req = Vec::new();
        let mut counts = vec![0; p];
        counts[0] = p + 2;
        rs.cluster.all_gather(&ask, &counts, &mut req);
        if me == 0 {
            // rank 0's request to every other rank
            rs.totals.reduce.messages += p as u64 - 1;
            rs.totals.reduce.values += (p as u64 - 1) * (p as u64 + 2);
        }
        if req[0] as usize != id {
            // the ranks serve the merges in the order rank 0 pulls them (Merges)
            eprintln!(
                "internal error: rank {me} serves merge {id} of an output while rank 0 asks for merge {}",
                req[0]
            );
            rs.cluster.abort(70);
        }
        if req[1] != 0.0 {
            self.stopped = true;
            rs.totals.reduce_seconds += t0.elapsed().as_secs_f64();
            return;
        }
        let n: Vec<usize> = req[2..2 + p].iter().map(|&x| x as usize).collect();
        let counts: Vec<usize> = n.iter().map(|k| k * self.rec).collect();
        let end = ((self.sent + n[me]) * self.rec).min(self.mine.len());
        let mine = &self.mine[(self.sent * self.rec).min(end)..end];
        self.sent += n[me];
        rs.cluster.gather(mine, &counts, &mut self.all);
        // a requested rank's records to rank 0
        if me != 0 && !mine.is_empty() {
            rs.totals.reduce.messages += 1;
            rs.totals.reduce.values += mine.len() as u64;
        }
        if me == 0 {
            let mut at = 0;
            for r in (0..p).filter(|&r| n[r] > 0) {
                self.buf[r].clear();
                self.buf[r].extend_from_slice(&self.all[at..at + counts[r]]);
                self.pos[r] = 0;
                self.left[r] -= n[r];
                at += counts[r];
            }
            self.all.clear();
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
        // records of 2 values, key 1: ids 1, 4, 9; an empty merge; records of 4
        let recs = vec![1.0, 10.0, 4.0, 40.0, 9.0, 90.0];
        let mut m = rs.merges(vec![(recs, 2, 1), (vec![], 3, 3), (vec![0.0, 1.0, 0.0, 2.0], 4, 3)]);
        m.list[0].per_round = 2;
        assert!(m.list[1].stopped, "a merge of no records is over at once");
        let mut out = vec![];
        let mut got = vec![];
        while m.pull(0, &mut rs, &mut out) {
            got.extend_from_slice(&out);
        }
        assert_eq!(got, [1.0, 10.0, 4.0, 40.0, 9.0, 90.0]);
        assert!(!m.pull(1, &mut rs, &mut out));
        assert!(m.pull(2, &mut rs, &mut out) && !m.pull(2, &mut rs, &mut out));
        // pulling the last merge first ends the earlier ones
        let mut m2 = rs.merges(vec![(vec![3.0, 30.0], 2, 1), (vec![0.0, 1.0, 0.0, 2.0], 4, 3)]);
        assert!(m2.pull(1, &mut rs, &mut out) && out == [0.0, 1.0, 0.0, 2.0]);
        assert!(m2.list[0].stopped);
        assert!(m.finish(&mut rs), "every record pulled");
        assert!(!m2.finish(&mut rs), "merge 0's record was never pulled");
        assert!(m.list.iter().chain(&m2.list).all(|x| x.stopped));
    }
}
