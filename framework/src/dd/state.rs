//! The NSCDD state a restart needs to continue bitwise: F_Γ of the last step's
//! interface copies (the next step's warm start), the grid of the last repartition,
//! the subdomain of each contact kept between repartitions, and the step count that
//! schedules them. Saved in `final.json` and checkpoints under `nscdd`
//! ([`crate::run`]) with the decomposition it belongs to; a restart with another
//! decomposition starts F_Γ from zero. On MPI ranks each rank holds F_Γ of its own
//! subdomains only: [`NscddOf::gather_state`] collects them on rank 0, so that the
//! state written by P ranks is the one-process state, and every rank loads all of
//! it (a restart on P′ ranks, or in one process, continues bitwise).

use super::{FGammaStore, Family, Grid, NscddOf};
use crate::model::ContactKey;
use serde::{Deserialize, Serialize};

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

impl<D: Family> NscddOf<D> {
    /// The state of the solver between steps (module docs); `None` on several MPI
    /// ranks (each holds only its subdomains' F_Γ: see [`NscddOf::gather_state`]).
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
            grid: self.grid.clone(),
            grid_empty: self.grid_empty,
            balance: self.balance,
            kept,
            f_gamma,
        }
    }

    /// The state on rank 0 (None elsewhere), collected from every rank's own
    /// subdomains; [`NscddOf::save_state`] in one process. Collective on MPI ranks:
    /// every rank calls it at the same step.
    pub fn gather_state(&mut self) -> Option<NscddState> {
        let Some(rs) = self.ranks.as_mut() else {
            return self.save_state();
        };
        let me = rs.cluster.rank();
        let dofs = D::V::default().as_ref().len();
        // (body, subdomain, F_Γ) of this rank's subdomains, flat
        let mut mine = Vec::new();
        for (b, e, v) in self.store.iter().filter(|e| rs.rank_of.get(e.1 as usize) == Some(&me)) {
            mine.extend([f64::from(b), f64::from(e)]);
            mine.extend_from_slice(v.as_ref());
        }
        let all = rs.gather_any_on_root(&mine);
        // the kept subdomains of this rank's contacts (all of them when every rank
        // holds every contact: each is some rank's)
        let mut mine = Vec::new();
        for (k, o) in self.kept.iter().filter(|e| rs.rank_of.get(e.1 as usize) == Some(&me)) {
            mine.extend([f64::from(k.i), f64::from(k.j), f64::from(k.feature), f64::from(*o)]);
        }
        let kept = rs.gather_any_on_root(&mine);
        if me != 0 {
            return None;
        }
        let mut f_gamma: Vec<(u32, u32, Vec<f64>)> = all
            .chunks_exact(2 + dofs)
            .map(|c| (c[0] as u32, c[1] as u32, c[2..].to_vec()))
            .collect();
        f_gamma.sort_unstable_by_key(|e| (e.0, e.1));
        let mut kept: Vec<(ContactKey, u32)> = kept
            .chunks_exact(4)
            .map(|x| {
                let key = ContactKey {
                    i: x[0] as u32,
                    j: x[1] as u32,
                    feature: x[2] as u32,
                };
                (key, x[3] as u32)
            })
            .collect();
        kept.sort_unstable_by_key(|e| e.0);
        Some(self.saved(f_gamma, kept))
    }

    /// Puts a saved state back (a solver made from the same decomposition, before its
    /// first step). `Ok(false)`: the state is of another decomposition and is left
    /// out (F_Γ starts from zero); an error: a malformed state.
    pub fn load_state(&mut self, s: NscddState) -> Result<bool, String> {
        if s.grid_of != [self.settings.nx, self.settings.ny, self.settings.nz] || s.by_model != self.by_model {
            return Ok(false);
        }
        // (rigid bodies only: by model the subdomains go on past the grid's cells)
        if !self.by_model {
            let cells = s.grid.as_ref().map_or(0, |g| g.len());
            if s.grid.is_some() && cells != (self.settings.nx * self.settings.ny * self.settings.nz) as usize {
                return Err(format!("grid: {cells} cells, the decomposition's {:?}", s.grid_of));
            }
            if let Some((k, e)) = s.kept.iter().enumerate().find(|(_, e)| e.1 as usize >= cells) {
                return Err(format!("kept[{k}]: subdomain {} of a grid of {cells} cells", e.1));
            }
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
