//! What an NSCDD step reports, and the per body / per contact view of its
//! decomposition for outputs.

use super::transport::TransportStats;
use crate::engine::StageTimes;
use crate::solver::SolveReport;

/// What one NSCDD step did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DdStepReport {
    /// `sweeps` counts NLGS sweeps (stages × sweeps_per_gluing); `converged` is both
    /// criteria; `norms` those of the merged sums; `residual` the natural-map
    /// residual of the written-back global solution.
    pub solve: SolveReport,
    pub stages: u32,
    pub contacts: usize,
    /// Subdomains that own at least one contact.
    pub subdomains: usize,
    pub interface_bodies: usize,
    pub links: usize,
    pub max_multiplicity: u32,
    /// egluing of the last check (before its gluing) and egluing / QuadWR.
    pub egluing: f64,
    pub egluing_rel: f64,
    /// Which criterion was met last (the one that held the iteration longest).
    pub prevailing: Prevailing,
    /// Whether the contact set was re-partitioned over a new grid at this step.
    pub repartitioned: bool,
    /// The largest subdomain's contacts over the mean ([`super::Census::imbalance`];
    /// 0 before the census).
    pub imbalance: f64,
    /// At a repartition: bodies with contacts before and after it whose set of
    /// subdomains changed (0 between repartitions).
    pub migrations: usize,
    /// Messages and values exchanged during the step.
    pub exchange: TransportStats,
    pub times: StageTimes,
    /// The counts outputs read, from the subdomains (exact on ranks; None: the
    /// step had no contact).
    pub census: Option<super::census::Census>,
}

/// Which stopping criterion was met last in a step: `Nlgs` when the gluing residual
/// was already below tol at the check before the converged one and the NLGS norms
/// were not (the contact solve held the iteration), `Gluing` the other way round,
/// `Both` when both became true at the same check (or at the first check). For a
/// step that did not converge: the criteria still unmet. `None`: no contacts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Prevailing {
    #[default]
    None,
    Nlgs,
    Gluing,
    Both,
}

impl Prevailing {
    pub fn name(self) -> &'static str {
        match self {
            Prevailing::None => "none",
            Prevailing::Nlgs => "nlgs",
            Prevailing::Gluing => "gluing",
            Prevailing::Both => "both",
        }
    }
    pub(super) fn of(now: (bool, bool), before: Option<(bool, bool)>) -> Self {
        match (now, before) {
            ((true, true), Some((true, false))) => Prevailing::Gluing,
            ((true, true), Some((false, true))) => Prevailing::Nlgs,
            ((true, true), _) | ((false, false), _) => Prevailing::Both,
            ((false, true), _) => Prevailing::Nlgs,
            ((true, false), _) => Prevailing::Gluing,
        }
    }
}

/// Per body and per contact fields of the last step's decomposition, for outputs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DdView {
    /// The subdomain owning most of the body's contacts (ties: the smaller id); −1
    /// for a body without contacts.
    pub body_subdomain: Vec<i32>,
    /// Number of subdomains holding a copy of the body (0: no contacts).
    pub multiplicity: Vec<u32>,
    /// Subdomain of each contact of the world's contact set.
    pub contact_subdomain: Vec<u32>,
    /// On MPI ranks: this process's part of the outputs.
    pub piece: Option<Piece>,
}

/// A rank's part of a decomposed run's outputs: the contacts of its subdomains, the
/// bodies whose [`DdView::body_subdomain`] is one of them (rank 0 also those without
/// contacts), written as its piece of each frame (`vtk/NAME_NNNNNN_RANK.vtp`, with
/// rank 0's `.pvtp` naming every piece).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Piece {
    pub rank: u32,
    pub ranks: u32,
    /// The rank of each subdomain.
    pub rank_of: Vec<u32>,
    /// With bodies held per rank: whether this rank writes each body without
    /// contacts (it holds it and the cell of its centre is its); `None`: rank 0
    /// writes them all.
    pub contactless: Option<Vec<bool>>,
}

impl Piece {
    /// Whether body k, of subdomain `s` (−1: no contacts), is in this piece.
    pub fn has_body(&self, k: usize, s: i32) -> bool {
        match self.rank_of.get(s.max(0) as usize) {
            Some(&r) if s >= 0 => r == self.rank,
            _ => match &self.contactless {
                Some(mine) => mine.get(k).copied().unwrap_or(false),
                None => self.rank == 0,
            },
        }
    }
    /// Whether a contact of subdomain `s` is in this piece.
    pub fn has_contact(&self, s: u32) -> bool {
        self.rank_of.get(s as usize).map_or(self.rank == 0, |&r| r == self.rank)
    }
}

impl<D: super::Family> super::NscddOf<D> {
    /// The last step's subdomain of each body and contact of `w` and the bodies'
    /// multiplicities (all −1 / 0 before the first step).
    pub fn view(&self, w: &D::World) -> DdView {
        let nb = D::n_bodies(w);
        let c = D::contacts(w);
        let d = &self.last;
        let mut v = DdView {
            body_subdomain: vec![-1; nb],
            multiplicity: (0..nb).map(|b| d.mult_of(b as u32)).collect(),
            contact_subdomain: Vec::new(),
            piece: self.ranks.as_ref().map(|rs| Piece {
                rank: rs.cluster.rank(),
                ranks: rs.cluster.size(),
                rank_of: rs.rank_of.clone(),
                contactless: self.owned_bodies(w),
            }),
        };
        if d.owner.len() != D::len(c) {
            return v;
        }
        v.contact_subdomain.clone_from(&d.owner);
        if self.local.whole_store {
            // a restart before its first step (contacts per rank, no step's counts
            // over the ranks yet): each body by its owner, as before any contact
            return v;
        }
        if self.local.held && self.local.body_sub.len() == nb {
            // contacts held per rank: the counts over every rank's
            v.body_subdomain.clone_from(&self.local.body_sub);
            return v;
        }
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(2 * d.owner.len());
        for (a, &s) in d.owner.iter().enumerate() {
            for g in D::contact_bodies(w, a) {
                pairs.push((g, s));
            }
        }
        pairs.sort_unstable();
        let mut best = vec![0usize; nb];
        let mut p = 0;
        while p < pairs.len() {
            let q = p + pairs[p..].iter().take_while(|e| **e == pairs[p]).count();
            let (g, s) = (pairs[p].0 as usize, pairs[p].1);
            // ascending subdomain ids: a strictly larger count wins, ties keep the smaller id
            if g < nb && q - p > best[g] {
                best[g] = q - p;
                v.body_subdomain[g] = s as i32;
            }
            p = q;
        }
        v
    }
}
