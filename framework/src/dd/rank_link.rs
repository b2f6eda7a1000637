//! The decentralized exchange between ranks: [`RankLink`], the buffers kept between
//! steps, and [`RankTransport`], the gluing schemes' [`Transport`] across ranks.

use super::cluster::Cluster;
use super::family::Family;
use super::subdomain::Subdomain;
use super::transport::{InProcess, Transport, TransportStats};
use std::time::Instant;

/// Buffers of the decentralized exchange between ranks, kept between steps.
#[derive(Default)]
pub struct RankLink {
    pub(super) me: u32,
    pub(super) rank_of: Vec<u32>,
    /// Ranks sharing interface bodies with this one (ascending).
    pub(super) peers: Vec<u32>,
    /// Per peer: packet headers (from, to, values) and values, then the message.
    pub(super) head: Vec<Vec<f64>>,
    pub(super) data: Vec<Vec<f64>>,
    pub(super) out: Vec<Vec<f64>>,
    pub(super) inbox: Vec<Vec<f64>>,
    /// (to, from, peer, offset, values) of the received packets, sorted.
    pub(super) index: Vec<(u32, u32, u32, u32, u32)>,
    /// Packets between two subdomains of this rank.
    pub(super) local: InProcess,
    pub(super) pending: bool,
    /// This step's counts (messages sent by this rank) and exchange rounds.
    pub(super) stats: TransportStats,
    pub(super) rounds: u64,
    /// Rounds of the last step.
    pub(super) rounds_step: u64,
    /// Seconds spent in the exchanges this step.
    pub(super) seconds: f64,
}

impl RankLink {
    /// Peers of this step's decomposition: the ranks of the own subdomains' neighbors.
    pub(super) fn setup<D: Family>(&mut self, subs: &[Subdomain<D>], rank_of: &[u32], me: u32) {
        self.me = me;
        self.rank_of.clear();
        self.rank_of.extend_from_slice(rank_of);
        self.peers.clear();
        for s in subs.iter().filter(|s| rank_of[s.id as usize] == me) {
            self.peers
                .extend(s.neighbors.iter().map(|n| rank_of[n.sub as usize]).filter(|&r| r != me));
        }
        self.peers.sort_unstable();
        self.peers.dedup();
        let np = self.peers.len();
        for v in [&mut self.head, &mut self.data, &mut self.out, &mut self.inbox] {
            v.resize_with(np, Vec::new);
            v.iter_mut().for_each(Vec::clear);
        }
        self.local.resize(subs.len());
        self.index.clear();
        self.pending = false;
    }
}

/// The decentralized scheme's [`Transport`] across ranks: packets to subdomains of
/// other ranks are collected per rank and sent as one message per peer when the
/// first packet of the round is read; packets between subdomains of this rank stay
/// in memory. A message is `[n, (from, to, values) × n, values…]`.
pub(super) struct RankTransport<'a> {
    pub(super) link: &'a mut RankLink,
    pub(super) cl: &'a mut dyn Cluster,
}

impl RankTransport<'_> {
    fn exchange(&mut self) {
        let l = &mut *self.link;
        l.pending = false;
        if l.peers.is_empty() {
            return;
        }
        let t0 = Instant::now();
        for p in 0..l.peers.len() {
            let o = &mut l.out[p];
            o.clear();
            o.push((l.head[p].len() / 3) as f64);
            o.extend_from_slice(&l.head[p]);
            o.extend_from_slice(&l.data[p]);
            l.head[p].clear();
            l.data[p].clear();
            l.stats.messages += 1;
            l.stats.values += o.len() as u64;
        }
        self.cl.exchange(&l.peers, &l.out, &mut l.inbox);
        l.index.clear();
        for (p, m) in l.inbox.iter().enumerate() {
            let n = m.first().copied().unwrap_or(0.0) as usize;
            let mut off = 1 + 3 * n;
            for h in m[1..1 + 3 * n].chunks_exact(3) {
                let len = h[2] as usize;
                l.index.push((h[1] as u32, h[0] as u32, p as u32, off as u32, len as u32));
                off += len;
            }
            assert_eq!(off, m.len(), "malformed interface message from rank {}", l.peers[p]);
        }
        l.index.sort_unstable();
        l.rounds += 1;
        l.seconds += t0.elapsed().as_secs_f64();
    }
}

impl Transport for RankTransport<'_> {
    fn send(&mut self, from: u32, to: u32, data: &[f64]) {
        let l = &mut *self.link;
        let r = l.rank_of[to as usize];
        if r == l.me {
            return l.local.send(from, to, data);
        }
        let p = l.peers.binary_search(&r).expect("a neighbor's rank is a peer");
        l.head[p].extend([from as f64, to as f64, data.len() as f64]);
        l.data[p].extend_from_slice(data);
        l.pending = true;
    }
    fn recv(&mut self, to: u32, from: u32, out: &mut Vec<f64>) {
        if self.link.pending {
            self.exchange();
        }
        let l = &mut *self.link;
        if l.rank_of[from as usize] == l.me {
            return l.local.recv(to, from, out);
        }
        out.clear();
        if let Ok(i) = l.index.binary_search_by_key(&(to, from), |e| (e.0, e.1)) {
            let (_, _, p, off, len) = l.index[i];
            out.extend_from_slice(&l.inbox[p as usize][off as usize..off as usize + len as usize]);
        }
    }
    fn stats(&self) -> TransportStats {
        self.link.stats
    }
    fn record(&mut self, _from: u32, _to: u32, _values: usize) {}
}
