//! The NSCDD state a restart needs to continue bitwise: F_Γ of the last step's
//! interface copies (the next step's warm start), the grid of the last repartition,
//! the subdomain of each contact kept between repartitions, and the step count that
//! schedules them. Saved in `final.json` and checkpoints under `nscdd`
//! ([`crate::run`]) with the decomposition it belongs to; a restart with another
//! decomposition starts F_Γ from zero.

use super::{FGammaStore, Family, Grid, NscddOf};
use crate::model::ContactKey;
use serde::{Deserialize, Serialize};

#[derive(Serialize, Deserialize)]
struct Saved {
    /// nx, ny, nz, by model: the decomposition the state belongs to.
    grid_of: [u32; 3],
    by_model: bool,
    steps: u64,
    grid: Option<Grid>,
    grid_empty: bool,
    kept: Vec<(ContactKey, u32)>,
    /// (body, subdomain, F_Γ).
    f_gamma: Vec<(u32, u32, Vec<f64>)>,
}

impl<D: Family> NscddOf<D> {
    /// The state of the solver between steps (module docs); `None` on several MPI
    /// ranks (each holds only its subdomains' F_Γ).
    pub fn save_state(&self) -> Option<serde_json::Value> {
        if self.ranks.is_some() {
            return None;
        }
        let s = Saved {
            grid_of: [self.settings.nx, self.settings.ny, self.settings.nz],
            by_model: self.by_model,
            steps: self.steps,
            grid: self.grid,
            grid_empty: self.grid_empty,
            kept: self.kept.clone(),
            f_gamma: self.store.iter().map(|(b, e, v)| (b, e, v.as_ref().to_vec())).collect(),
        };
        Some(serde_json::to_value(s).expect("plain data"))
    }

    /// Puts a saved state back (a solver made from the same decomposition, before its
    /// first step). `Ok(false)`: the state is of another decomposition and is left
    /// out (F_Γ starts from zero); an error: a malformed state.
    pub fn load_state(&mut self, state: &serde_json::Value) -> Result<bool, String> {
        let s: Saved = Saved::deserialize(state).map_err(|e| format!("not an NSCDD state: {e}"))?;
        if s.grid_of != [self.settings.nx, self.settings.ny, self.settings.nz] || s.by_model != self.by_model || self.ranks.is_some() {
            return Ok(false);
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
        self.store = FGammaStore::from_entries(entries);
        self.steps = s.steps;
        self.grid = s.grid;
        self.grid_empty = s.grid_empty;
        self.kept = s.kept;
        self.kept.sort_unstable_by_key(|x| x.0);
        Ok(true)
    }
}
