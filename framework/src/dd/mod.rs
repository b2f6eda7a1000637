//! NSCDD: non-smooth contact domain decomposition (DESIGN.md §3), written once for
//! every body family ([`family::Family`]: 2D rigid bodies [`Nscdd`], 3D rigid bodies
//! [`Nscdd3`]).
//!
//! One step with [`NscddOf::step`]: free velocity, detection and the contact set as in
//! [`crate::engine`]; then the contact set is split over an nx × ny (× nz) grid
//! ([`partition`]), each subdomain holding copies of its bodies with M̂_E = M̂/m
//! ([`subdomain`]); then, until convergence,
//!
//! ```text
//! repeat {
//!     every subdomain: `sweeps_per_gluing` NLGS sweeps on its copies (in parallel)
//!     exchange the interface copies' velocities (Transport, scheme)
//!     gluing: ΔF_Γ = L⁻¹ M̂_E [V] per interface body, V_E += M̂_E⁻¹ ΔF_Γ
//!     every `check_every` stages: LMGC90 criterion on the Sums merged over the
//!         subdomains (in subdomain order) ∧ egluing / QuadWR < tol
//! }
//! ```
//!
//! then each interface body's velocity is the average of its copies, and the global
//! velocities and contact impulses are written back, so that `update_positions`,
//! reactions and outputs work unchanged. F_Γ is kept between steps per (body,
//! subdomain) ([`partition::FGammaStore`]); a body whose copies changed is glued
//! once before the first sweep. (With copies of equal M̂_E the exact gluing puts all
//! copies at their mean, so a kept F_Γ starts the copies where that first gluing
//! would: V_free + M̂⁻¹ Σ_E H_E r_E with the warm-start impulses.) Gluing and residual: [`gluing`]; schemes:
//! [`schemes`]; exchange: [`transport`].
//!
//! Repartition: a new grid over the contact points every `repartition_every` steps;
//! in between, a contact found in the previous step, by key, keeps its subdomain and
//! a new one goes to the cell of the last grid holding its point. Migrations are
//! counted at repartitions. A scene's `[decomposition]` is a [`DdConfig`].
//!
//! Counting: a *stage* is `sweeps_per_gluing` sweeps and one gluing; the check
//! period `check_every` and the limit `max_sweeps / sweeps_per_gluing` (rounded up)
//! count stages. With one subdomain and one sweep per stage this is the one-domain
//! NLGS, bitwise: the same sweep on the same data in the same order.
//!
//! Threads ([`team`]): subdomains are split into `threads` groups swept (and, with
//! the decentralized scheme, glued) in parallel by threads kept for the whole step; a subdomain's sweep reads and writes
//! only its own data and every reduction runs in subdomain order, so the result does
//! not depend on the number of threads.

mod anderson;
pub mod attach;
mod cells;
mod census;
pub mod cluster;
mod config;
pub mod family;
pub mod first_part;
pub mod gluing;
mod grid;
mod local;
mod local_families;
#[cfg(feature = "mpi")]
pub mod mpi;
mod owned;
mod owner;
pub mod partition;
mod rank_ask;
mod rank_balance;
mod rank_fresh;
mod rank_link;
pub mod rank_merge;
mod rank_reduce;
mod rank_share;
mod rank_solved;
mod rank_totals;
pub mod ranks;
mod reactions;
mod report;
pub mod schemes;
mod shells;
mod stage;
pub use stage::Stage;
mod state;
pub use first_part::LoadedPart;
pub use state::{NscddState, RestartPart};
pub mod subdomain;
pub mod team;
pub mod transport;

use crate::model::ContactKey;
pub use attach::{Attached, EntityInfo, LocalPart, OwnCells, RankCells, Rounds, SolvedOn};
pub use census::Census;
pub use cluster::{Cluster, Solo};
pub use config::{Balance, DdConfig};
pub use family::{Family, Rigid, Rigid2, Rigid3};
pub use partition::{Decomposition, FGammaStore, FamilyOwners, Grid, Interface};
pub use rank_solved::with_rounds;
pub use ranks::RankState;
pub use report::{DdStepReport, DdView, Piece, Prevailing};
pub use schemes::Scheme;
pub use subdomain::{Subdomain, Subdomain2, Subdomain3, SubdomainSolver};
pub use transport::{InProcess, Transport, TransportStats};

use crate::engine::Diverged;
use crate::norms::{Norms, Sums, VANISHING};
use gluing::GluePartial;
use schemes::GlueBuffers;

/// NSCDD settings.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DdSettings {
    /// Grid of subdomains over the contact points' bounding box.
    pub nx: u32,
    pub ny: u32,
    /// 3D only (1 in 2D).
    pub nz: u32,
    pub scheme: Scheme,
    /// NLGS sweeps per gluing stage (LMGC90: 1).
    pub sweeps_per_gluing: u32,
    /// Threads sweeping the subdomains (1: the calling thread only).
    pub threads: usize,
}

impl Default for DdSettings {
    fn default() -> Self {
        DdSettings {
            nx: 1,
            ny: 1,
            nz: 1,
            scheme: Scheme::Decentralized,
            sweeps_per_gluing: 1,
            threads: 1,
        }
    }
}

/// The NSCDD solver state kept between steps, for the body family `D`.
pub struct NscddOf<D: Family> {
    pub settings: DdSettings,
    /// F_Γ of the last step's interface copies.
    pub store: FGammaStore<D::V>,
    /// The last step's decomposition (copies as after the last gluing, before the
    /// averaging).
    pub last: Decomposition<D>,
    /// Re-partition over a new grid every this many steps (0 counts as 1); between
    /// repartitions persisting contacts keep their subdomain and new ones go to the
    /// cell of the last grid that holds their point.
    pub repartition_every: u32,
    /// Load balancing between the periodic repartitions: when the imbalance of a
    /// step (the largest subdomain's contacts over the mean, from the census, so the
    /// same for any number of threads or ranks) exceeds this factor times the
    /// imbalance of the last repartition's step, the step after next re-partitions
    /// (the next one has already shared its state as a step before no repartition).
    pub rebalance: Option<f64>,
    /// Balanced cuts instead of uniform cells ([`Grid::balanced`]).
    pub balanced_grid: bool,
    /// The imbalance of the last repartition's step, and the value of `steps` at
    /// which a re-partition is due.
    balance: Balance,
    /// Steps done by this solver.
    pub steps: u64,
    /// The grid of the last repartition.
    pub grid: Option<Grid>,
    /// With attached families ([`attach`]): their contacts in subdomains of their own,
    /// family f's on the grid's cells `(f + 1) · cells ..`; else they share the
    /// rigid contacts' subdomains.
    pub by_model: bool,
    /// Subdomain of each attached family's contact (this step).
    fam_owner: Vec<Vec<u32>>,
    /// The attached families' contact points (this step), one range per family.
    fam_points: Vec<[f64; 3]>,
    /// The families' contacts (before [`Self::keep_own`]): over the ranks when
    /// they detect whole; read only then (a distributed repartition counts its
    /// own, [`Self::repartition_local`]).
    fam_total: usize,
    fam_ranges: Vec<std::ops::Range<usize>>,
    /// Which attached families are stepped in part on this rank this step
    /// ([`Attached::solved_on`]).
    fam_stepped: Vec<bool>,
    /// Which attached families detected in this rank's cells only this step
    /// ([`Attached::after_free_velocity_own`]).
    fam_own: Vec<bool>,
    /// Every rank's cells of each family detecting in them: its next detection's.
    fam_cells: Vec<Option<cells::CellIndex>>,
    /// Whether the steps may hold bodies and contacts per rank ([`local`],
    /// [`owned`]): rigid bodies alone, or attached families that name the world
    /// bodies they touch; by model, with at least as many grid cells as ranks.
    /// Decided at the first step (or [`Self::start_ranks`]).
    held_ok: Option<bool>,
    /// Whether the outputs' sums (the observed bodies' reactions, the sums over
    /// bodies) are added per subdomain ([`reactions`], [`census`]): the scenes that
    /// may hold bodies per rank, whatever the number of ranks (by model on more
    /// ranks than cells too), so that one process and any rank count add alike.
    sums_per_sub: Option<bool>,
    /// The report of the step in progress.
    pending: DdStepReport,
    /// Owner of each contact of the last step, by key (sorted).
    kept: Vec<(ContactKey, u32)>,
    /// Whether the last grid was made over no contact (then the next step
    /// re-partitions).
    grid_empty: bool,
    transport: InProcess,
    bufs: GlueBuffers,
    /// Threads or one, by their measured speed ([`team::ThreadChoice`]).
    choice: team::ThreadChoice,
    /// The subdomain threads, kept across steps.
    workers: team::Workers,
    /// Anderson mixing of the stages (`[solver] method = "anderson"`).
    mixer: anderson::StageMixer,
    v_free: Vec<D::V>,
    /// Set for a multi-process run ([`ranks`]): this process sweeps and glues only
    /// its ranks' subdomains.
    ranks: Option<RankState>,
    /// On ranks, whether contacts are held per rank between repartitions
    /// ([`local`]; rigid bodies only), and that mode's state.
    pub local_contacts: bool,
    local: local::Local,
    /// A fresh scene loaded in part on this rank ([`Self::start_from`]).
    loaded: Option<LoadedPart>,
}

/// NSCDD of 2D rigid bodies.
pub type Nscdd = NscddOf<Rigid2>;
/// NSCDD of 3D rigid bodies.
pub type Nscdd3 = NscddOf<Rigid3>;

impl<D: Family> NscddOf<D> {
    pub fn new(settings: DdSettings) -> Self {
        NscddOf {
            settings,
            store: FGammaStore::default(),
            last: Decomposition::default(),
            repartition_every: 1,
            rebalance: None,
            balanced_grid: false,
            balance: Balance::default(),
            steps: 0,
            grid: None,
            by_model: false,
            fam_owner: Vec::new(),
            fam_points: Vec::new(),
            fam_total: 0,
            fam_ranges: Vec::new(),
            fam_stepped: Vec::new(),
            fam_own: Vec::new(),
            fam_cells: Vec::new(),
            held_ok: None,
            sums_per_sub: None,
            pending: DdStepReport::default(),
            kept: Vec::new(),
            grid_empty: false,
            transport: InProcess::default(),
            bufs: GlueBuffers::default(),
            choice: team::ThreadChoice::default(),
            workers: team::Workers::default(),
            mixer: anderson::StageMixer::default(),
            v_free: Vec::new(),
            ranks: None,
            local_contacts: true,
            local: local::Local::default(),
            loaded: None,
        }
    }

    /// Runs the subdomains over the ranks of `cluster` ([`ranks`]); every rank must
    /// step the same world with the same settings. Err: the grid has fewer
    /// subdomains than there are ranks (by model: at least two models, the rigid
    /// contacts and one family's, over the grid's cells).
    pub fn with_cluster(mut self, cluster: Box<dyn Cluster>) -> Result<Self, String> {
        let s = &self.settings;
        let models = if self.by_model { 2 } else { 1 };
        let n = models * s.nx as u64 * s.ny as u64 * s.nz.max(1) as u64;
        if (cluster.size() as u64) > n {
            return Err(format!(
                "{} ranks for {n} subdomains: every rank needs at least one subdomain (use at most {n} ranks or a finer [decomposition])",
                cluster.size()
            ));
        }
        self.ranks = Some(RankState::new(cluster));
        Ok(self)
    }

    /// The multi-process state (None in one process).
    pub fn ranks_mut(&mut self) -> Option<&mut RankState> {
        self.ranks.as_mut()
    }

    /// Whether the next steps may leave out what only the outputs' view
    /// ([`NscddOf::view`]) reads: on ranks with contacts held per rank, each body's
    /// subdomain (a collective count over the ranks). Every rank sets the same; a run
    /// sets it for the steps after which it writes no frame.
    pub fn skip_view(&mut self, skip: bool) {
        self.local.skip_view = skip;
    }

    /// A fresh scene whose world holds this rank's part since loading
    /// ([`crate::scene::part`]): the first step starts from the provisional grid
    /// and ranks the loader computed, as it would compute them from the whole world.
    pub fn start_from(&mut self, part: LoadedPart) {
        self.loaded = Some(part);
    }

    /// Before a run's first frame: on ranks, each world reduced to its rank's part
    /// when the first step will run per rank ([`Self::start_held`], which the first
    /// step calls otherwise), a fresh run's or a restart's, so that the first frame
    /// too is written in pieces by the bodies' owners instead of whole by rank 0.
    /// `touched`: the world bodies the scene's body families touch
    /// ([`attach::touched`]; none without families; `None`: a family may touch any
    /// body, and every rank steps every body).
    pub fn start_ranks(&mut self, w: &mut D::World, touched: Option<attach::Touched>) {
        let ok = self.decide_held(|| touched);
        self.start_held(w, ok);
    }

    /// [`Self::held_ok`], decided once: `touched` gives the attached families'
    /// world bodies (every rank steps them, [`owned`]).
    fn decide_held(&mut self, touched: impl FnOnce() -> Option<attach::Touched>) -> bool {
        if let Some(ok) = self.held_ok {
            return ok;
        }
        // by model, each family's subdomain of a cell goes with the cell: at least
        // as many cells as ranks
        let s = &self.settings;
        let cells = s.nx as u64 * s.ny as u64 * s.nz.max(1) as u64;
        let fit = !self.by_model || self.ranks.as_ref().is_none_or(|r| u64::from(r.cluster.size()) <= cells);
        let touched = touched();
        self.sums_per_sub = Some(touched.is_some());
        let ok = match touched {
            Some(t) if fit => {
                self.local.models = if self.by_model { 1 + t.families } else { 1 };
                self.local.owned.set_shared(t.ids);
                self.local.owned.set_reach(t.reach);
                true
            }
            _ => false,
        };
        self.held_ok = Some(ok);
        ok
    }

    /// Whether this scene's steps may hold bodies and contacts per rank (before it
    /// is decided: rigid bodies alone, `no_families`, not by model).
    fn held_scene(&self, no_families: bool) -> bool {
        self.held_ok.unwrap_or(no_families && !self.by_model)
    }

    /// Whether the outputs' sums are added per subdomain ([`Self::sums_per_sub`];
    /// before it is decided, as [`Self::held_scene`]).
    fn sums_per_subdomain(&self, no_families: bool) -> bool {
        self.sums_per_sub.unwrap_or(no_families && !self.by_model)
    }

    /// Re-partitions every `k` steps (see [`Nscdd::repartition_every`]).
    pub fn with_repartition_every(mut self, k: u32) -> Self {
        self.repartition_every = k;
        self
    }

    /// This step's decomposition of `w.contacts`: a new grid every
    /// `repartition_every` steps, else the kept owners.
    fn partition(&mut self, w: &D::World, fams: &mut [&mut dyn Attached<D>], rep: &mut DdStepReport) {
        let s = &self.settings;
        let c = D::contacts(w);
        let nc = D::len(c);
        let ranges = std::mem::take(&mut self.fam_ranges);
        let repart = self.repartitions();
        let (grid, owner) = match &self.grid {
            Some(g) if !repart => (g.clone(), partition::kept_owners::<D>(c, g, &self.kept)),
            _ => {
                let pts = (0..nc).map(|a| D::point(c, a)).chain(self.fam_points.iter().copied());
                // contacts held per rank: the grid of the distributed repartition
                let g = match &self.local.new_grid {
                    Some((g, _)) => g.clone(),
                    None if self.balanced_grid => Grid::balanced_over(pts, s.nx, s.ny, s.nz),
                    None => Grid::over(pts, s.nx, s.ny, s.nz),
                };
                let owner = (0..nc).map(|a| g.cell_of(D::point(c, a))).collect();
                (g, owner)
            }
        };
        let models = if self.by_model { 1 + fams.len() } else { 1 };
        let ns = grid.len() * models;
        self.fam_owner.resize_with(fams.len(), Vec::new);
        for (f, r) in ranges.iter().enumerate() {
            let base = if self.by_model { (f + 1) * grid.len() } else { 0 } as u32;
            let o = &mut self.fam_owner[f];
            o.clear();
            o.extend(self.fam_points[r.clone()].iter().map(|&p| base + grid.cell_of(p)));
        }
        self.fam_ranges = ranges;
        // limited shells ([`shells`]): on a repartition step, the kept F_Γ routed
        let mut start = self.start_shells(w, repart);
        // the last step's copies, for the migrations (routed with limited shells)
        let before = (repart && self.steps > 0).then(|| match start.as_mut().and_then(|s| s.1.take()) {
            Some(routed) => (routed, true),
            None => (partition::copies(&self.last), false),
        });
        if repart {
            self.grid = Some(grid.clone());
            let total = self.local.new_grid.take().map_or(nc + self.fam_total, |(_, t)| t);
            self.grid_empty = total == 0;
        }
        // several processes: each builds only the subdomains of its rank (chosen by
        // the distributed repartition when contacts are held per rank)
        let build = self.ranks.as_mut().map(|rs| rs.assign(&owner, ns, repart && !self.local.now));
        rank_solved::solved_on(w, fams, (&self.fam_owner, self.ranks.as_mut()), &mut self.fam_stepped);
        let fo = FamilyOwners {
            fams: &*fams,
            owner: &self.fam_owner,
        };
        let (local, families) = (&self.local, !fams.is_empty());
        let mut shells = |subs: &mut [Subdomain<D>], first: Option<&[u32]>| {
            let rs = self.ranks.as_mut().expect("ranks");
            // (the families' copies routed after their split: none without families)
            match (start.as_ref().and_then(|(asked, _)| shells::near_of::<D>(local, w, asked)), first) {
                (Some(near), None) => rs.fill_shells_near(subs, &near),
                (Some(near), Some(first)) if families => return rs.route_family_copies(subs, &near, first),
                (None, None) => rs.fill_shells(subs),
                (_, Some(_)) => {}
            }
            Vec::new()
        };
        let shells = self.local.now.then_some(&mut shells as partition::Shells<'_, D>);
        self.last = partition::decompose_owned::<D>(w, &self.v_free, grid, owner, ns, &self.store, build.as_deref(), &fo, shells);
        // contacts held per rank: the other ranks' F_Γ are not kept up to date here
        // (the copies' starting velocities hold F_Γ and the warm starts, families'
        // parts included: made once, after it, `Subdomain::init_velocities`)
        if let (true, Some(rs)) = (self.local.now, self.ranks.as_mut()) {
            rs.fresh_f_gamma(&mut self.last, &self.store);
            let slot = |g: u32| D::held_slot(w, g as usize);
            for s in self.last.subs.iter_mut().filter(|s| rs.is_own(s.id)) {
                s.init_velocities(&self.v_free, &slot);
            }
        }
        rep.repartitioned = repart;
        if let Some((before, routed)) = before {
            let ranks = self.ranks.as_mut().filter(|_| routed);
            rep.migrations = shells::migrations(ranks, &self.last, &before);
        }
        self.kept.clear();
        self.kept.extend((0..nc).map(|a| D::key(c, a)).zip(self.last.owner.iter().copied()));
        self.kept.sort_unstable_by_key(|e| e.0);
        self.steps += 1;
    }

    /// Advances `w` by one step, the contact problem solved by NSCDD.
    pub fn step(&mut self, w: &mut D::World) -> Result<DdStepReport, Diverged> {
        self.step_families(w, &mut [])
    }

    /// Advances `w` by one step with the attached body families `fams` ([`attach`]),
    /// the contact problem of all of them solved by NSCDD (over the ranks of a
    /// cluster as well: every rank holds the families too, sweeps its subdomains'
    /// parts and receives the others' packed results, [`LocalPart::pack`]).
    pub fn step_families(&mut self, w: &mut D::World, fams: &mut [&mut dyn Attached<D>]) -> Result<DdStepReport, Diverged> {
        self.pending = DdStepReport::default();
        let ok = self.decide_held(|| {
            let fams: Vec<&dyn Attached<D>> = fams.iter().map(|f| &**f as &dyn Attached<D>).collect();
            attach::touched(w, &fams)
        });
        self.start_held(w, ok);
        let base = D::step_with(w, &mut Stage { dd: self, fams });
        self.after_step();
        let base = base?;
        let mut rep = std::mem::take(&mut self.pending);
        rep.solve = base.solve;
        rep.contacts = base.contacts;
        rep.times = base.times;
        Ok(rep)
    }

    /// The attached families' contact points of the step, one range per family
    /// (after their [`Attached::build`]: the partition's, and a distributed
    /// repartition's, input).
    fn family_points(&mut self, fams: &[&mut dyn Attached<D>]) {
        self.fam_points.clear();
        self.fam_ranges.clear();
        for f in fams {
            let a = self.fam_points.len();
            f.points(&mut self.fam_points);
            self.fam_ranges.push(a..self.fam_points.len());
        }
    }

    /// The NSCDD iteration on `self.last`, then the write-back into `w`.
    fn solve(&mut self, w: &mut D::World, fams: &mut [&mut dyn Attached<D>], rep: &mut DdStepReport) {
        let set = self.settings.clone();
        let sv = D::solver(w).clone();
        // (the step count already counts this step)
        let next_repartitions = self.repartitions();
        let d = &mut self.last;
        self.transport.resize(d.subs.len());
        self.transport.reset_stats();
        rep.subdomains = d.subs.iter().filter(|s| s.n_contacts() > 0).count();
        rep.interface_bodies = d.iface.len();
        rep.links = d.iface.links();
        rep.max_multiplicity = d.mult.iter().map(|x| x.1).max().unwrap_or(0);
        let mut fresh = d.iface.fresh.iter().any(|&f| f);
        let mut total = D::len(D::contacts(w)) + self.fam_points.len();
        if let (true, Some(rs)) = (self.local.now, self.ranks.as_mut()) {
            // contacts held per rank: whether any rank has one; the interface's
            // counts and freshness over the ranks ([`shells`])
            let t = shells::interface_totals(rs, d, total);
            (total, fresh) = (t.contacts, t.fresh);
            (rep.interface_bodies, rep.links, rep.max_multiplicity) = (t.bodies, t.links, t.max_multiplicity);
        }
        if total == 0 {
            rep.solve.converged = true;
            self.store.keep(&d.subs);
            rank_solved::write_back_alone(w, fams, (&self.fam_stepped, &self.fam_cells), self.ranks.as_mut());
            return;
        }
        let per = set.sweeps_per_gluing.max(1);
        let max_stages = sv.max_sweeps.div_ceil(per).max(1);
        let k = sv.check_every.max(1);
        let mut before: Option<(bool, bool)> = None;
        let mut converged = |sums: &Sums, g: &GluePartial, rep: &mut DdStepReport| {
            rep.solve.norms = Norms::from_sums(sums, sv.tolerance);
            let quad_wr = if sums.nactif > 0 && sums.sum_wrwr > VANISHING && sums.sum_wrr > VANISHING {
                (sums.sum_wrwr / sums.nactif as f64).sqrt()
            } else {
                0.0
            };
            rep.egluing = g.egluing();
            rep.egluing_rel = g.relative(quad_wr);
            let now = (rep.solve.norms.converged(sv.norm), rep.egluing_rel < sv.tolerance);
            rep.prevailing = Prevailing::of(now, before);
            before = Some(now);
            rep.solve.converged = now == (true, true);
            // an overflow stops the stages, unconverged
            rep.solve.converged || !sums.is_finite()
        };
        // threads, or one while they do not pay (timing only: any count gives the same result)
        let threads = self.choice.threads(self.steps, set.threads);
        let t0 = std::time::Instant::now();
        let stages = if let Some(rs) = self.ranks.as_mut() {
            let hybrid = (threads, &mut self.workers);
            let mixer = (sv.method == crate::solver::Method::Anderson).then_some(&mut self.mixer);
            // bodies stepped per rank, the subdomains kept on their ranks next step:
            // only the copies of the bodies this rank steps come back (`rank_share`)
            // (the same choice on every rank: the all-gathers that follow are collective)
            // (with limited shells before a repartition too: the next step routes
            // the kept F_Γ, [`shells`])
            let requests = (self.local.now && (self.local.limited || !next_repartitions)).then(|| D::active(w));
            let (stages, stats) = ranks::iterate(
                rs,
                d,
                set.scheme,
                (per, sv.relaxation, max_stages, k),
                hybrid,
                (mixer, requests, fresh),
                |s, g| converged(s, g, rep),
            );
            rep.exchange = stats;
            stages
        } else {
            let here = (&mut self.transport, &mut self.bufs, &mut self.mixer, &mut self.workers);
            let stages = schemes::iterate_here(d, here, (&set, &sv), (threads, per, max_stages, k), |s, g| converged(s, g, rep));
            rep.exchange = self.transport.stats();
            stages
        };
        self.choice.record(self.steps, t0.elapsed().as_secs_f64(), stages);
        rep.stages = stages;
        rep.solve.sweeps = stages * per;
        // the step's end by requests: the own subdomains and the copies received
        // are read (the store keeps every subdomain's F_Γ: a copy without an entry
        // would be glued as new at the next step)
        match self.ranks.as_mut().and_then(|rs| rs.answered.take().map(|a| (a, rs))) {
            Some((got, rs)) => {
                let (rank_of, me) = (&rs.rank_of, rs.cluster.rank());
                attach::write_back_held(d, w, Some((&|s: u32| rank_of[s as usize] == me, &got)));
                rs.answered = Some(got);
            }
            None => attach::write_back(d, w),
        }
        self.store.keep(&d.subs);
        let on = (&self.fam_stepped[..], &self.fam_cells[..]);
        rep.solve.residual = attach::write_back_families(d, w, (fams, on, &self.fam_owner), self.ranks.as_mut());
        self.local.body_sub.clear();
        if let (true, false, Some(rs)) = (self.local.now, self.local.skip_view, self.ranks.as_mut()) {
            self.local.body_sub = shells::body_subdomains(rs, d, D::n_bodies(w));
        }
    }
}

/// One NSCDD step of `w` with a solver state (F_Γ kept in `state` between steps).
pub fn step(w: &mut crate::world::World2, state: &mut Nscdd) -> Result<DdStepReport, Diverged> {
    state.step(w)
}
