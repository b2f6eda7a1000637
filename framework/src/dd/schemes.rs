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
#[derive(Default)]
pub struct GlueBuffers {
    packets: Vec<Vec<f64>>,
    c: ChainBuffers,
    send: Vec<f64>,
}

/// Buffers of the chain solves of one subdomain's gluing ([`glue_sub`]).
#[derive(Default)]
pub struct ChainBuffers {
    chain: Vec<f64>,
    dv: Vec<f64>,
    scratch: ChainScratch,
}

/// One gluing stage: exchange, chain solves, F_Γ and velocity updates. Returns each
/// subdomain's share of the gluing residual, measured on the velocities before the
/// update. With `only_fresh`, only the bodies marked fresh are updated (the start of
/// a step).
pub fn glue_stage<D: Family>(
    subs: &mut [&mut Subdomain<D>],
    iface: &Interface,
    scheme: Scheme,
    t: &mut dyn Transport,
    only_fresh: bool,
    b: &mut GlueBuffers,
) -> Vec<GluePartial> {
    match scheme {
        Scheme::Decentralized => decentralized(subs, iface, t, only_fresh, b),
        Scheme::Centralized => centralized(subs, iface, t, only_fresh, b),
    }
}

fn decentralized<D: Family>(
    subs: &mut [&mut Subdomain<D>],
    iface: &Interface,
    t: &mut dyn Transport,
    only_fresh: bool,
    b: &mut GlueBuffers,
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
pub fn post<D: Family>(s: &Subdomain<D>, out: &mut Vec<Vec<f64>>) {
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
    packets: &[Vec<f64>],
    iface: &Interface,
    only_fresh: bool,
    b: &mut ChainBuffers,
) -> GluePartial {
    let mut part = GluePartial::default();
    for q in 0..s.slots() {
        let ib = s.iface_ib[q] as usize;
        let k = s.iface_k[q] as usize;
        let d = iface.dofs[ib] as usize;
        b.chain.clear();
        for &(ni, p) in &s.chain[s.chain_start[q] as usize..s.chain_start[q + 1] as usize] {
            if ni == OWN {
                s.interface_velocity(p as usize, &mut b.chain);
            } else {
                let p = p as usize;
                b.chain.extend_from_slice(&packets[ni as usize][p..p + d]);
            }
        }
        accumulate(&mut part, &b.chain, d, k, iface, ib);
        if !only_fresh || iface.fresh[ib] {
            b.dv.resize(b.chain.len(), 0.0);
            chain_increments(&b.chain, d, &mut b.dv, &mut b.scratch);
            s.glue(q, &b.dv[k * d..(k + 1) * d]);
        }
    }
    part
}

/// The residual share of one copy: its chain's links if it is the first copy.
#[inline(always)]
fn accumulate(part: &mut GluePartial, chain: &[f64], d: usize, k: usize, iface: &Interface, ib: usize) {
    let (space, rho2, w) = (iface.space[ib] as usize, iface.rho2[ib], iface.weight[ib]);
    if k == 0 {
        part.jump2 += w * link_sum(chain, d, space, rho2);
        part.links += (chain.len() / d) as u64 - 1;
    }
    part.v2 += w * norm2(&chain[k * d..(k + 1) * d], space, rho2);
    part.copies += 1;
}

const ROOT: u32 = 0;

/// The root's part of the centralized gluing: from `all[s]` (subdomain s's
/// interface velocities, slot order) every chain solved once, `out[s]` the copies'
/// increments (zero where not updated) and `parts[s]` the residual shares, per
/// subdomain in slot order (as the decentralized scheme). `meta(s)`: subdomain s's
/// (`iface_ib`, `iface_k`). Shared by the in-process and the multi-process schemes.
pub(super) fn root_solve<'m>(
    all: &[Vec<f64>],
    out: &mut [Vec<f64>],
    parts: &mut [GluePartial],
    iface: &Interface,
    meta: impl Fn(usize) -> (&'m [u32], &'m [u32]),
    only_fresh: bool,
    c: &mut ChainBuffers,
) {
    for (o, a) in out.iter_mut().zip(all) {
        o.clear();
        o.resize(a.len(), 0.0);
    }
    let at = |x: usize| (iface.sub[x] as usize, iface.off[x] as usize);
    // solve every chain once
    for ib in 0..iface.len() {
        let (r, d) = (iface.copies(ib), iface.dofs[ib] as usize);
        c.chain.clear();
        for x in r.clone() {
            let (s, o) = at(x);
            c.chain.extend_from_slice(&all[s][o..o + d]);
        }
        if !only_fresh || iface.fresh[ib] {
            c.dv.resize(c.chain.len(), 0.0);
            chain_increments(&c.chain, d, &mut c.dv, &mut c.scratch);
            for (k, x) in r.enumerate() {
                let (s, o) = at(x);
                out[s][o..o + d].copy_from_slice(&c.dv[k * d..(k + 1) * d]);
            }
        }
    }
    // residual shares, per subdomain in slot order
    for (s, part) in parts.iter_mut().enumerate() {
        let (ibs, ks) = meta(s);
        for q in 0..ibs.len() {
            let (ib, d) = (ibs[q] as usize, iface.dofs[ibs[q] as usize] as usize);
            c.chain.clear();
            for x in iface.copies(ib) {
                let (t, o) = at(x);
                c.chain.extend_from_slice(&all[t][o..o + d]);
            }
            accumulate(part, &c.chain, d, ks[q] as usize, iface, ib);
        }
    }
}

fn centralized<D: Family>(
    subs: &mut [&mut Subdomain<D>],
    iface: &Interface,
    t: &mut dyn Transport,
    only_fresh: bool,
    b: &mut GlueBuffers,
) -> Vec<GluePartial> {
    let ns = subs.len();
    // gather
    for s in subs.iter() {
        b.send.clear();
        for q in 0..s.slots() {
            s.interface_velocity(q, &mut b.send);
        }
        t.send(s.id, ROOT, &b.send);
    }
    b.packets.resize_with(b.packets.len().max(2 * ns), Vec::new);
    let (all, out) = b.packets.split_at_mut(ns);
    for (s, a) in all.iter_mut().enumerate() {
        t.recv(ROOT, s as u32, a);
    }
    let mut parts = vec![GluePartial::default(); ns];
    root_solve(
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
        for q in 0..s.slots() {
            let (o, e) = (s.iface_off[q] as usize, s.iface_off[q + 1] as usize);
            if !only_fresh || iface.fresh[s.iface_ib[q] as usize] {
                s.glue(q, &b.send[o..e]);
            }
        }
    }
    parts
}

/// The NSCDD iteration in this process (every subdomain here): at most `max_stages`
/// stages of `per` sweeps and one gluing, a check every `k` stages (the sums
/// reduced in subdomain order); returns the stages run.
pub(super) fn iterate_here<D: Family>(
    d: &mut super::partition::Decomposition<D>,
    (transport, bufs, mixer, workers): (
        &mut super::InProcess,
        &mut GlueBuffers,
        &mut super::anderson::StageMixer,
        &mut super::team::Workers,
    ),
    (set, sv): (&super::DdSettings, &crate::solver::SolverSettings),
    (threads, per, max_stages, k): (usize, u32, u32, u32),
    mut converged: impl FnMut(&crate::norms::Sums, &GluePartial) -> bool,
) -> u32 {
    let iface = &d.iface;
    let anderson = sv.method == crate::solver::Method::Anderson;
    super::team::with_team(&mut d.subs, (threads, &|_| true), iface, workers, |team| {
        if iface.fresh.iter().any(|&f| f) {
            team.with_all(|subs| glue_stage(subs, iface, set.scheme, transport, true, bufs));
        }
        if anderson {
            team.with_all(|subs| mixer.start(subs, &|_| true));
        }
        let (stages, ok) = crate::solver::check_loop(max_stages, k, |check| {
            // sweeps and gluing; with `check`, the sums reduced in subdomain order
            let (sums, parts) = team.stage(per, sv.relaxation, check, set.scheme, transport, bufs);
            let done = check && {
                let mut g = GluePartial::default();
                for p in &parts {
                    g.merge(p);
                }
                converged(&sums, &g)
            };
            if anderson && !done {
                team.with_all(|subs| mixer.after(subs, &|_| true, &mut crate::solver::anderson::InOrder));
            }
            done
        });
        if anderson && !ok {
            team.with_all(|subs| mixer.give_up(subs, &|_| true));
        }
        stages
    })
}
