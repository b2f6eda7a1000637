//! A scene's decomposition ([`DdConfig`]: the `[decomposition]` section) and the
//! load balance between repartitions ([`Balance`]).

use super::{DdSettings, Family, Nscdd, Nscdd3, NscddOf};

/// A scene's decomposition: the NSCDD settings and the repartition period (the
/// scene's `[decomposition]` section, or the command line's `--subdomains`).
#[derive(Clone, Debug, PartialEq)]
pub struct DdConfig {
    pub dd: DdSettings,
    /// Re-partition every this many steps (≥ 1).
    pub repartition_every: u32,
    /// `by_model = true`: subdomains by model as well as by geometry (scenes with
    /// deformable bodies; run by the deformable-body plugin).
    pub by_model: bool,
    /// Re-partition between the periodic repartitions too, when the load imbalance
    /// has grown by this factor since the last one ([`NscddOf::rebalance`]).
    pub rebalance: Option<f64>,
    /// `grid = "balanced"`: multi-jagged cuts that split the contact points evenly
    /// ([`super::Grid::balanced`]) instead of uniform cells.
    pub balanced_grid: bool,
}

impl Default for DdConfig {
    fn default() -> Self {
        DdConfig {
            dd: DdSettings::default(),
            repartition_every: 1,
            by_model: false,
            rebalance: None,
            balanced_grid: false,
        }
    }
}

impl DdConfig {
    /// The solver state for a run of the body family `D`.
    pub fn solver_of<D: Family>(&self) -> NscddOf<D> {
        let mut s = NscddOf::new(self.dd.clone()).with_repartition_every(self.repartition_every);
        s.by_model = self.by_model;
        s.rebalance = self.rebalance;
        s.balanced_grid = self.balanced_grid;
        s
    }

    /// The solver state for a run.
    pub fn solver(&self) -> Nscdd {
        self.solver_of()
    }

    /// The solver state for a 3D run.
    pub fn solver3(&self) -> Nscdd3 {
        self.solver_of()
    }

    /// Whether the sample can hold the grid: `nx × ny` may not exceed the number of
    /// movable bodies (a subdomain is a set of contacts, each touching a movable
    /// body, and a body's contacts can split over several subdomains only if there
    /// are more bodies than subdomains). Err: (the key at fault, the message).
    pub fn check_capacity(&self, movable: usize) -> Result<(), (&'static str, String)> {
        let n = self.dd.nx as u64 * self.dd.ny as u64 * self.dd.nz.max(1) as u64;
        if n > movable as u64 {
            let dims = if self.dd.nz > 1 {
                format!("{} × {} × {}", self.dd.nx, self.dd.ny, self.dd.nz)
            } else {
                format!("{} × {}", self.dd.nx, self.dd.ny)
            };
            return Err((
                "nx",
                format!("{dims} = {n} subdomains is more than the sample can hold: at most one subdomain per movable body ({movable})"),
            ));
        }
        Ok(())
    }
}

/// The load balance between repartitions ([`NscddOf::rebalance`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Balance {
    /// The imbalance at the last repartition's step (0: none yet).
    pub at_repartition: f64,
    /// A re-partition is due when `steps` reaches this value.
    pub due: Option<u64>,
}

impl Balance {
    /// Takes the census' imbalance of a step (`steps`: the solver's count, this step
    /// included): a repartition's sets the reference; past `factor` times it, a
    /// re-partition becomes due at the step after next (unless one is due already).
    pub(super) fn observe(&mut self, imbalance: f64, repartitioned: bool, steps: u64, factor: Option<f64>) {
        if repartitioned {
            self.at_repartition = imbalance;
        } else if let Some(f) = factor {
            if imbalance > f * self.at_repartition && self.due.is_none_or(|d| d < steps) {
                self.due = Some(steps + 1);
            }
        }
    }
}
