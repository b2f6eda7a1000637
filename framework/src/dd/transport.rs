//! Exchange of interface data between subdomains.
//!
//! The gluing stage only moves short packets of copy velocities (the degrees of
//! freedom of each interface copy, as `f64`s: 3 per 2D rigid body, 6 per 3D one)
//! between subdomains, addressed by subdomain id. [`Transport`] is
//! that point-to-point layer: [`InProcess`] keeps one mailbox per (receiver, sender)
//! pair for threads and tests; an MPI transport (cargo feature `mpi`, later) maps
//! subdomains to ranks. Both schemes of [`super::schemes`] are written against it.
//!
//! A round is: every sender `send`s, then every receiver `recv`s what was addressed
//! to it. Packets between one pair are not queued: a second `send` before the
//! `recv` replaces the first (each scheme sends at most one packet per pair and
//! round).

/// Counts of what went through a transport (messages to oneself are not counted).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct TransportStats {
    pub messages: u64,
    /// Number of `f64` values sent.
    pub values: u64,
}

/// Point-to-point exchange of interface packets (copy velocities, as the `f64`s of
/// their degrees of freedom) between subdomains.
pub trait Transport {
    /// Posts `data` from subdomain `from` to subdomain `to`.
    fn send(&mut self, from: u32, to: u32, data: &[f64]);
    /// Takes the packet that `from` posted to `to` in this round into `out`
    /// (cleared first; left empty when none was posted).
    fn recv(&mut self, to: u32, from: u32, out: &mut Vec<f64>);
    fn stats(&self) -> TransportStats;
    /// Counts a packet of `values` numbers from `from` to `to` that went through
    /// shared memory instead (the threads of [`super::team`]), as `send` would.
    fn record(&mut self, from: u32, to: u32, values: usize);
}

/// In-process transport: one mailbox per (receiver, sender) pair, buffers reused.
#[derive(Default)]
pub struct InProcess {
    n: usize,
    boxes: Vec<Vec<f64>>,
    stats: TransportStats,
}

impl InProcess {
    /// Makes room for `n` subdomains (keeps the counts).
    pub fn resize(&mut self, n: usize) {
        if n != self.n {
            self.n = n;
            self.boxes.clear();
            self.boxes.resize_with(n * n, Vec::new);
        }
    }
    pub fn reset_stats(&mut self) {
        self.stats = TransportStats::default();
    }
}

impl Transport for InProcess {
    fn send(&mut self, from: u32, to: u32, data: &[f64]) {
        let b = &mut self.boxes[to as usize * self.n + from as usize];
        b.clear();
        b.extend_from_slice(data);
        self.record(from, to, data.len());
    }
    fn recv(&mut self, to: u32, from: u32, out: &mut Vec<f64>) {
        out.clear();
        std::mem::swap(out, &mut self.boxes[to as usize * self.n + from as usize]);
    }
    fn stats(&self) -> TransportStats {
        self.stats
    }
    fn record(&mut self, from: u32, to: u32, values: usize) {
        if from != to {
            self.stats.messages += 1;
            self.stats.values += values as u64;
        }
    }
}
