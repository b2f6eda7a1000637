//! The two communication schemes of the gluing stage (DESIGN.md §3).
//!
//! - **Decentralized**: every subdomain sends, to each subdomain it shares interface
//!   bodies with, its copies' velocities of those bodies; then each subdomain solves
//!   the chain of each of its interface bodies ([`super::gluing::chain_increments`])
//!   and applies its own copy's increment. A face body (m = 2) uses only the data of
//!   the two subdomains its link joins; a corner body the data of its m subdomains,
//!   all of which share it. The chain is solved redundantly, once per copy, with the
//!   same inputs in the same order: every copy gets the same numbers.
//! - **Centralized**: every subdomain sends all its interface velocities to the root
//!   (subdomain 0), which solves every chain once and sends each subdomain its
//!   copies' increments.
//!
//! Both call the same chain solve on the same velocities, so they give bitwise the
//! same increments, and they accumulate the gluing residual per subdomain in the same
//! order (slot order; the links of a body counted by the subdomain of its first
//! copy), so the residuals agree bitwise as well.

use super::family::Family;
use super::gluing::{chain_increments, link_sum, norm2, ChainScratch, GluePartial};
use super::partition::Interface;
use super::subdomain::{Subdomain, SubdomainSolver, OWN};
use super::transport::Transport;

/// The communication scheme of the gluing stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scheme {
    Decentralized,
    Centralized,
}

/// Buffers reused between gluing stages.
pub struct GlueBuffers<V> {
    packets: Vec<Vec<V>>,
    c: ChainBuffers<V>,
    send: Vec<V>,
}

impl<V> Default for GlueBuffers<V> {
    fn default() -> Self {
        GlueBuffers {
            packets: Vec::new(),
            c: ChainBuffers::default(),
            send: Vec::new(),
        }
    }
}

/// Buffers of the chain solves of one subdomain's gluing ([`glue_sub`]).
pub struct ChainBuffers<V> {
    chain: Vec<V>,
    dv: Vec<V>,
    scratch: ChainScratch<V>,
}

impl<V> Default for ChainBuffers<V> {
    fn default() -> Self {
        ChainBuffers {
            chain: Vec::new(),
            dv: Vec::new(),
            scratch: ChainScratch::default(),
        }
    }
}

/// One gluing stage: exchange, chain solves, F_Γ and velocity updates. Returns each
/// subdomain's share of the gluing residual, measured on the velocities before the
/// update. With `only_fresh`, only the bodies marked fresh are updated (the start of
/// a step).
pub fn glue_stage<D: Family>(
    subs: &mut [&mut Subdomain<D>],
    iface: &Interface,
    scheme: Scheme,
    t: &mut dyn Transport<D::V>,
    only_fresh: bool,
    b: &mut GlueBuffers<D::V>,
) -> Vec<GluePartial> {
    match scheme {
        Scheme::Decentralized => decentralized(subs, iface, t, only_fresh, b),
        Scheme::Centralized => centralized(subs, iface, t, only_fresh, b),
    }
}

fn decentralized<D: Family>(
    subs: &mut [&mut Subdomain<D>],
    iface: &Interface,
    t: &mut dyn Transport<D::V>,
    only_fresh: bool,
    b: &mut GlueBuffers<D::V>,
) -> Vec<GluePartial> {
    for s in subs.iter() {
        for nbr in &s.neighbors {
            b.send.clear();
            s.interface_velocities(&nbr.slots, &mut b.send);
            t.send(s.id, nbr.sub, &b.send);
        }
    }
    let mut parts = vec![GluePartial::default(); subs.len()];
    for (s, part) in subs.iter_mut().zip(parts.iter_mut()) {
        b.packets.resize_with(b.packets.len().max(s.neighbors.len()), Vec::new);
        for (ni, nbr) in s.neighbors.iter().enumerate() {
            t.recv(s.id, nbr.sub, &mut b.packets[ni]);
        }
        *part = glue_sub(s, &b.packets, iface, only_fresh, &mut b.c);
    }
    parts
}

/// The decentralized scheme's packets of subdomain `s`: `out[ni]` its copies'
/// velocities of the bodies shared with neighbor `ni` (what [`decentralized`] sends).
pub fn post<D: Family>(s: &Subdomain<D>, out: &mut Vec<Vec<D::V>>) {
    out.resize_with(s.neighbors.len(), Vec::new);
    for (o, nbr) in out.iter_mut().zip(&s.neighbors) {
        o.clear();
        s.interface_velocities(&nbr.slots, o);
    }
}

/// The decentralized gluing of one subdomain once its neighbors' packets are in
/// (`packets[ni]`: what neighbor `ni` posted to `s`): each interface body's chain
/// solved, the own copy's increment applied. Returns the subdomain's residual share,
/// measured on the velocities before the update.
pub fn glue_sub<D: Family>(
    s: &mut Subdomain<D>,
    packets: &[Vec<D::V>],
    iface: &Interface,
    only_fresh: bool,
    b: &mut ChainBuffers<D::V>,
) -> GluePartial {
    let mut part = GluePartial::default();
    for q in 0..s.iface.len() {
        let ib = s.iface_ib[q] as usize;
        let k = s.iface_k[q] as usize;
        b.chain.clear();
        for &(ni, p) in &s.chain[s.chain_start[q] as usize..s.chain_start[q + 1] as usize] {
            b.chain.push(if ni == OWN {
                s.interface_velocity(p as usize)
            } else {
                packets[ni as usize][p as usize]
            });
        }
        accumulate(&mut part, &b.chain, k, D::SPACE, iface.rho2[ib]);
        if !only_fresh || iface.fresh[ib] {
            b.dv.resize(b.chain.len(), D::V::default());
            chain_increments(&b.chain, &mut b.dv, &mut b.scratch);
            s.glue(q, b.dv[k]);
        }
    }
    part
}

/// The residual share of one copy: its chain's links if it is the first copy.
fn accumulate<V: Copy + Default + AsRef<[f64]> + AsMut<[f64]>>(part: &mut GluePartial, chain: &[V], k: usize, space: usize, rho2: f64) {
    if k == 0 {
        part.jump2 += link_sum(chain, space, rho2);
        part.links += chain.len() as u64 - 1;
    }
    part.v2 += norm2(&chain[k], space, rho2);
    part.copies += 1;
}

const ROOT: u32 = 0;

/// The root's part of the centralized gluing: from `all[s]` (subdomain s's
/// interface velocities, slot order) every chain solved once, `out[s]` the copies'
/// increments (zero where not updated) and `parts[s]` the residual shares, per
/// subdomain in slot order (as the decentralized scheme). `meta(s)`: subdomain s's
/// (`iface_ib`, `iface_k`). Shared by the in-process and the multi-process schemes.
pub(super) fn root_solve<'m, D: Family>(
    all: &[Vec<D::V>],
    out: &mut [Vec<D::V>],
    parts: &mut [GluePartial],
    iface: &Interface,
    meta: impl Fn(usize) -> (&'m [u32], &'m [u32]),
    only_fresh: bool,
    c: &mut ChainBuffers<D::V>,
) {
    for (o, a) in out.iter_mut().zip(all) {
        o.clear();
        o.resize(a.len(), D::V::default());
    }
    // solve every chain once
    for ib in 0..iface.len() {
        let r = iface.copies(ib);
        c.chain.clear();
        c.chain
            .extend(r.clone().map(|k| all[iface.sub[k] as usize][iface.slot[k] as usize]));
        if !only_fresh || iface.fresh[ib] {
            c.dv.resize(c.chain.len(), D::V::default());
            chain_increments(&c.chain, &mut c.dv, &mut c.scratch);
            for (k, x) in r.enumerate() {
                out[iface.sub[x] as usize][iface.slot[x] as usize] = c.dv[k];
            }
        }
    }
    // residual shares, per subdomain in slot order
    for (s, part) in parts.iter_mut().enumerate() {
        let (ibs, ks) = meta(s);
        for q in 0..all[s].len() {
            let ib = ibs[q] as usize;
            c.chain.clear();
            c.chain
                .extend(iface.copies(ib).map(|x| all[iface.sub[x] as usize][iface.slot[x] as usize]));
            accumulate(part, &c.chain, ks[q] as usize, D::SPACE, iface.rho2[ib]);
        }
    }
}

fn centralized<D: Family>(
    subs: &mut [&mut Subdomain<D>],
    iface: &Interface,
    t: &mut dyn Transport<D::V>,
    only_fresh: bool,
    b: &mut GlueBuffers<D::V>,
) -> Vec<GluePartial> {
    let ns = subs.len();
    // gather
    for s in subs.iter() {
        b.send.clear();
        for q in 0..s.iface.len() {
            b.send.push(s.interface_velocity(q));
        }
        t.send(s.id, ROOT, &b.send);
    }
    b.packets.resize_with(b.packets.len().max(2 * ns), Vec::new);
    let (all, out) = b.packets.split_at_mut(ns);
    for (s, a) in all.iter_mut().enumerate() {
        t.recv(ROOT, s as u32, a);
    }
    let mut parts = vec![GluePartial::default(); ns];
    root_solve::<D>(
        all,
        out,
        &mut parts,
        iface,
        |s| (&subs[s].iface_ib, &subs[s].iface_k),
        only_fresh,
        &mut b.c,
    );
    // scatter
    for (s, o) in out.iter().enumerate().take(ns) {
        t.send(ROOT, s as u32, o);
    }
    for s in subs.iter_mut() {
        t.recv(s.id, ROOT, &mut b.send);
        for q in 0..b.send.len() {
            if !only_fresh || iface.fresh[s.iface_ib[q] as usize] {
                s.glue(q, b.send[q]);
            }
        }
    }
    parts
}
