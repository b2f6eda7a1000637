//! The NSCDD state a restart needs to continue bitwise: F_Γ of the last step's
//! interface copies (the next step's warm start), the grid of the last repartition,
//! the subdomain of each contact kept between repartitions, and the step count that
//! schedules them. Saved in `final.json` and checkpoints under `nscdd`
//! ([`crate::run`]) with the decomposition it belongs to; a restart with another
//! decomposition starts F_Γ from zero. On MPI ranks each rank holds F_Γ of its own
//! subdomains only: [`NscddOf::state_on_ranks`] collects them on rank 0, which
//! merges every rank's kept contacts as it writes them, so that the state written
//! by P ranks is the one-process state, and every rank loads all of it (a restart on
//! P′ ranks, or in one process, continues bitwise).

use super::rank_merge::Pull;
use super::{FGammaStore, Family, Grid, NscddOf};
use crate::model::ContactKey;
use serde::{Deserialize, Serialize};
use std::cell::RefCell;

/// The solver's state as saved (module docs): written and read by serde directly,
/// never held as a JSON tree (a 55 000-sphere state keeps ≈ 150 000 contacts here).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NscddState {
    /// nx, ny, nz, by model: the decomposition the state belongs to.
    grid_of: [u32; 3],
    by_model: bool,
    steps: u64,
    grid: Option<Grid>,
    grid_empty: bool,
    kept: Vec<(ContactKey, u32)>,
    /// (body, subdomain, F_Γ).
    f_gamma: Vec<(u32, u32, Vec<f64>)>,
    /// The load balance between repartitions (absent from states written before it:
    /// none due, the reference taken at the next repartition).
    #[serde(default)]
    balance: super::Balance,
}

/// [`NscddState`] as written with its kept contacts pulled one at a time (rank 0's
/// merge of every rank's, [`NscddOf::state_on_ranks`]): the same fields in the same
/// order, so the same text.
#[derive(Serialize)]
pub struct StateOut<'s, 'p> {
    grid_of: &'s [u32; 3],
    by_model: bool,
    steps: u64,
    grid: &'s Option<Grid>,
    grid_empty: bool,
    kept: KeptOut<'p>,
    f_gamma: &'s [(u32, u32, Vec<f64>)],
    balance: &'s super::Balance,
}

/// Kept contacts pulled as `[i, j, feature, subdomain]` records, ascending by key.
pub struct KeptOut<'p>(RefCell<Option<Pull<'p>>>);

impl Serialize for KeptOut<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut pull = self.0.borrow_mut().take();
        let mut rec = Vec::new();
        s.collect_seq(std::iter::from_fn(|| {
            let pull = pull.as_mut()?;
            let key = |x: &[f64]| ContactKey {
                i: x[0] as u32,
                j: x[1] as u32,
                feature: x[2] as u32,
            };
            pull(&mut rec).then(|| (key(&rec), rec[3] as u32))
        }))
    }
}

impl NscddState {
    /// The state as written, its kept contacts (none held here) from `kept`.
    pub fn with_kept<'s, 'p>(&'s self, kept: Pull<'p>) -> StateOut<'s, 'p> {
        StateOut {
            grid_of: &self.grid_of,
            by_model: self.by_model,
            steps: self.steps,
            grid: &self.grid,
            grid_empty: self.grid_empty,
            kept: KeptOut(RefCell::new(Some(kept))),
            f_gamma: &self.f_gamma,
            balance: &self.balance,
        }
    }
}

/// The contacts one MPI rank keeps of a saved state (a restart on P ranks with
/// contacts held per rank, [`NscddState::rank_part`]): those of the subdomains the
/// first step after the restart gives the rank — the kept subdomain of a contact
/// whose key the state keeps, else the saved grid's cell of its point
/// ([`super::owner`]), the cells' ranks balanced by the kept contacts as
/// `NscddOf::start_restarted` balances them. A restart that streams the state keeps
/// only those ([`crate::scene::restart_scene_on`]), instead of every contact of the
/// sample on every rank until the first step drops the others.
pub struct RestartPart {
    grid: Grid,
    kept: Vec<(ContactKey, u32)>,
    rank_of: Vec<u32>,
    me: u32,
    at: usize,
    /// A hash of every contact read, kept or not ([`RestartPart::digest`]).
    seen: std::collections::hash_map::DefaultHasher,
}

impl RestartPart {
    /// Whether this rank keeps the contact of `key` at point `p` (keys mostly
    /// ascending, as a state lists them: the search gallops from the last one).
    pub fn keeps(&mut self, key: ContactKey, p: [f64; 3]) -> bool {
        let mut owner = super::owner::OwnerOf::new(&self.kept, &self.grid);
        owner.at = self.at;
        let o = owner.of(key, p);
        self.at = owner.at;
        self.rank_of.get(o as usize) == Some(&self.me)
    }

    /// Adds a contact read (kept by this rank or not) to the digest: the same on
    /// every rank, so that the ranks' agreement on the initial state still covers
    /// every contact of the file ([`RestartPart::digest`]).
    pub fn saw(&mut self, values: impl IntoIterator<Item = u64>) {
        use std::hash::Hasher;
        for v in values {
            self.seen.write_u64(v);
        }
    }

    /// Back to the state before the first contact was decided (the search's
    /// start; the decisions never depend on it), for a second pass over the same
    /// contacts. The digest is left as it is.
    pub fn rewind(&mut self) {
        self.at = 0;
    }

    /// The digest of every contact read ([`RestartPart::saw`]).
    pub fn digest(&self) -> u64 {
        use std::hash::Hasher;
        self.seen.finish()
    }

    /// This rank's cells in the first step after the restart, against which the
    /// saved bodies' boxes grown by `alert` are tested (the halo the step keeps:
    /// [`crate::scene::part::restart_on`] builds only those bodies).
    pub fn halo(&self, space: usize, alert: f64) -> super::first_part::Halo {
        super::first_part::Halo::of(&self.grid, &self.rank_of, self.me, space, alert)
    }
}

impl NscddState {
    /// The part of rank `me` of `ranks` when a run of the decomposition `grid_of`
    /// (`by_model`) restarts from this state with contacts held per rank; `None`
    /// when every rank must load every contact (one rank; by model; a state of
    /// another decomposition or without a grid; a malformed state, which
    /// `NscddOf::load_state` refuses).
    pub fn rank_part(&self, grid_of: [u32; 3], by_model: bool, ranks: u32, me: u32) -> Option<RestartPart> {
        let grid = self.grid.as_ref()?;
        if ranks < 2 || by_model != self.by_model || self.grid_of != grid_of || self.grid_empty {
            return None;
        }
        // a grid of other cells, or too few for the ranks: the run refuses it (exit 2)
        let cells: u64 = grid_of.iter().map(|&n| u64::from(n)).product();
        if grid.len() as u64 != cells || cells < u64::from(ranks) {
            return None;
        }
        // (a kept subdomain past the grid: `NscddOf::load_state` refuses the state)
        if self.kept.iter().any(|e| e.1 as u64 >= cells) {
            return None;
        }
        let mut kept = self.kept.clone();
        kept.sort_unstable_by_key(|x| x.0);
        Some(RestartPart {
            grid: grid.clone(),
            rank_of: super::rank_balance::ranks_by_owner(kept.iter().map(|e| e.1), grid.len(), ranks),
            kept,
            me,
            at: 0,
            seen: Default::default(),
        })
    }
}

impl<D: Family> NscddOf<D> {
    /// The state of the solver between steps (module docs); `None` on several MPI
    /// ranks (each holds only its subdomains' F_Γ: see [`NscddOf::state_on_ranks`]).
    pub fn save_state(&self) -> Option<NscddState> {
        if self.ranks.is_some() {
            return None;
        }
        let f_gamma = self.store.iter().map(|(b, e, v)| (b, e, v.as_ref().to_vec())).collect();
        Some(self.saved(f_gamma, self.kept.clone()))
    }

    fn saved(&self, f_gamma: Vec<(u32, u32, Vec<f64>)>, kept: Vec<(ContactKey, u32)>) -> NscddState {
        NscddState {
            grid_of: [self.settings.nx, self.settings.ny, self.settings.nz],
            by_model: self.by_model,
            steps: self.steps,
            // (before the first step: none, as in one process, even where the
            // loader gave ranks the first step's provisional grid)
            grid: self.grid.clone().filter(|_| self.steps > 0),
            grid_empty: self.grid_empty,
            balance: self.balance,
            kept,
            f_gamma,
        }
    }

    /// On MPI ranks (collective; `None` in one process): the state on rank 0 without
    /// its kept contacts (F_Γ collected from every rank's own subdomains), and this
    /// rank's kept contacts as `[i, j, feature, subdomain]` records ascending by key,
    /// which rank 0 merges as it writes them ([`NscddState::with_kept`],
    /// [`super::rank_merge`]): the state written by P ranks is the one-process state.
    pub fn state_on_ranks(&mut self) -> Option<(Option<NscddState>, Vec<f64>)> {
        let rs = self.ranks.as_mut()?;
        let me = rs.cluster.rank();
        let dofs = D::V::default().as_ref().len();
        // (body, subdomain, F_Γ) of this rank's subdomains, flat
        let mut mine = Vec::new();
        for (b, e, v) in self.store.iter().filter(|e| rs.is_own(e.1)) {
            mine.extend([f64::from(b), f64::from(e)]);
            mine.extend_from_slice(v.as_ref());
        }
        let all = rs.gather_any_on_root(&mine);
        // the kept subdomains of this rank's contacts (all of them when every rank
        // holds every contact: each is some rank's)
        let mut own: Vec<&(ContactKey, u32)> = self.kept.iter().filter(|e| rs.is_own(e.1)).collect();
        own.sort_unstable_by_key(|e| e.0);
        let kept = own
            .iter()
            .flat_map(|(k, o)| [f64::from(k.i), f64::from(k.j), f64::from(k.feature), f64::from(*o)])
            .collect();
        if me != 0 {
            return Some((None, kept));
        }
        let mut f_gamma: Vec<(u32, u32, Vec<f64>)> = all
            .chunks_exact(2 + dofs)
            .map(|c| (c[0] as u32, c[1] as u32, c[2..].to_vec()))
            .collect();
        f_gamma.sort_unstable_by_key(|e| (e.0, e.1));
        Some((Some(self.saved(f_gamma, Vec::new())), kept))
    }

    /// Puts a saved state back (a solver made from the same decomposition, before its
    /// first step). `Ok(false)`: the state is of another decomposition and is left
    /// out (F_Γ starts from zero); an error: a malformed state.
    pub fn load_state(&mut self, s: NscddState) -> Result<bool, String> {
        if s.grid_of != [self.settings.nx, self.settings.ny, self.settings.nz] || s.by_model != self.by_model {
            return Ok(false);
        }
        // (the kept contacts are the world's, in the grid's cells; by model the F_Γ's
        // subdomains go on past the cells, the families')
        let cells = s.grid.as_ref().map_or(0, |g| g.len());
        if s.grid.is_some() && cells != (self.settings.nx * self.settings.ny * self.settings.nz) as usize {
            return Err(format!("grid: {cells} cells, the decomposition's {:?}", s.grid_of));
        }
        if let Some((k, e)) = s.kept.iter().enumerate().find(|(_, e)| e.1 as usize >= cells) {
            return Err(format!("kept[{k}]: subdomain {} of a grid of {cells} cells", e.1));
        }
        if !self.by_model {
            if let Some((k, e)) = s.f_gamma.iter().enumerate().find(|(_, e)| e.1 as usize >= cells) {
                return Err(format!("f_gamma[{k}]: subdomain {} of a grid of {cells} cells", e.1));
            }
        }
        let dofs = D::V::default().as_ref().len();
        let mut entries = Vec::with_capacity(s.f_gamma.len());
        for (k, (b, e, v)) in s.f_gamma.into_iter().enumerate() {
            if v.len() != dofs || !v.iter().all(|x| x.is_finite()) {
                return Err(format!("f_gamma[{k}]: {dofs} finite numbers expected"));
            }
            let mut x = D::V::default();
            x.as_mut().copy_from_slice(&v);
            entries.push((b, e, x));
        }
        let b = s.balance.at_repartition;
        if !(b.is_finite() && b >= 0.0) {
            return Err(format!("balance.at_repartition: a finite number ≥ 0 expected, got {b}"));
        }
        self.store = FGammaStore::from_entries(entries);
        self.steps = s.steps;
        self.balance = s.balance;
        self.grid = s.grid;
        self.grid_empty = s.grid_empty;
        self.kept = s.kept;
        self.kept.sort_unstable_by_key(|x| x.0);
        Ok(true)
    }
}
