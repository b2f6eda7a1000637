//! Questions to the ranks of other subdomains, point to point: a rank asks, for
//! pairs (subdomain, key), values that only the subdomain's rank holds (a copy's
//! velocity, a copy's kept F_Γ), and each rank answers what it was asked.
//!
//! ```text
//! counts    how many pairs this rank asks of each other rank: one all-to-all of
//!           one value per pair of ranks
//! requests  the pairs, sent to their subdomains' ranks (point to point, with the
//!           ranks that ask of this one or are asked by it: a symmetric relation)
//! answers   each asking rank the values of its pairs, in its order (the same peers)
//! ```
//!
//! The messages are as long as what is asked (the rank boundaries), and go only to
//! the ranks concerned. Used by the end of a step ([`super::rank_share`]), the
//! fresh bodies' F_Γ ([`super::rank_fresh`]) and the counts of shared bodies
//! ([`super::shells`]); [`RankState::send_ranks`], its first round alone, sends the
//! shells' bodies.

use super::ranks::RankState;
use std::time::Instant;

impl RankState {
    /// Values to some ranks, point to point (`out[r]`: the values for rank r, empty
    /// for itself and the ranks sent nothing): one all-to-all of the lengths, then
    /// one exchange with the ranks sent to or receiving from this one (a symmetric
    /// relation). Returns those ranks (ascending) and what each sent this one.
    /// Collective.
    pub(super) fn send_ranks(&mut self, mut out: Vec<Vec<f64>>) -> (Vec<u32>, Vec<Vec<f64>>) {
        let t0 = Instant::now();
        let (me, np) = (self.cluster.rank(), self.cluster.size() as usize);
        debug_assert_eq!(out.len(), np, "one list a rank");
        let to: Vec<u64> = out.iter().map(|v| v.len() as u64).collect();
        let mut from = Vec::new();
        self.cluster.all_to_all(&to, &mut from);
        self.sent_p2p(np - 1, np - 1);
        let peers: Vec<u32> = (0..np as u32)
            .filter(|&r| r != me && (to[r as usize] > 0 || from[r as usize] > 0))
            .collect();
        let sent: Vec<Vec<f64>> = peers.iter().map(|&r| std::mem::take(&mut out[r as usize])).collect();
        let mut inbox = vec![Vec::new(); peers.len()];
        self.cluster.exchange(&peers, &sent, &mut inbox);
        self.sent_p2p(sent.iter().filter(|o| !o.is_empty()).count(), sent.iter().map(Vec::len).sum());
        self.totals.reduce_seconds += t0.elapsed().as_secs_f64();
        (peers, inbox)
    }

    /// The values of the pairs `asks` = (subdomain, key), `n` per pair, from the
    /// subdomains' ranks, in the order of `asks` (every subdomain another rank's);
    /// `answer(s, key, out)` appends this rank's values of a pair asked of it.
    /// Collective.
    pub(super) fn ask_ranks(&mut self, asks: &[(u32, u32)], n: usize, answer: impl Fn(u32, u32, &mut Vec<f64>)) -> Vec<f64> {
        let (me, np) = (self.cluster.rank(), self.cluster.size() as usize);
        // the pairs asked of each rank, in the order of `asks`
        let mut of: Vec<Vec<usize>> = vec![Vec::new(); np];
        for (i, &(s, _)) in asks.iter().enumerate() {
            let r = self.rank_of[s as usize];
            debug_assert_ne!(r, me, "a pair of another rank's subdomain");
            of[r as usize].push(i);
        }
        let out: Vec<Vec<f64>> = of
            .iter()
            .map(|v| v.iter().flat_map(|&i| [f64::from(asks[i].0), f64::from(asks[i].1)]).collect())
            .collect();
        let (peers, mut inbox) = self.send_ranks(out);
        // (the requests' time counted by `send_ranks`)
        let t0 = Instant::now();
        let out: Vec<Vec<f64>> = inbox
            .iter()
            .map(|q| {
                let mut a = Vec::with_capacity(q.len() / 2 * n);
                for x in q.chunks_exact(2) {
                    debug_assert_eq!(self.rank_of[x[0] as usize], me, "asked of its rank");
                    answer(x[0] as u32, x[1] as u32, &mut a);
                }
                a
            })
            .collect();
        self.cluster.exchange(&peers, &out, &mut inbox);
        self.sent_p2p(out.iter().filter(|o| !o.is_empty()).count(), out.iter().map(Vec::len).sum());
        let mut values = vec![0.0; asks.len() * n];
        for (&r, got) in peers.iter().zip(&inbox) {
            debug_assert_eq!(got.len(), of[r as usize].len() * n, "one answer a pair");
            for (&i, v) in of[r as usize].iter().zip(got.chunks_exact(n)) {
                values[i * n..(i + 1) * n].copy_from_slice(v);
            }
        }
        self.totals.reduce_seconds += t0.elapsed().as_secs_f64();
        values
    }

    /// Records point-to-point messages and values this rank sent.
    fn sent_p2p(&mut self, messages: usize, values: usize) {
        self.totals.reduce.messages += messages as u64;
        self.totals.reduce.values += values as u64;
    }
}
