//! Frictional contact problems in local form (`u = W r + q`), read from the JSON
//! exchange format, solved by NLGS. (Placeholder API; implemented with `solve-fc`.)

use crate::error::InputError;
use crate::norms::Criterion;
use std::path::Path;

/// Stopping test of `solve-fc`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FcNorm {
    /// Natural-map residual ‖F(r)‖/‖q‖ < tol.
    Natural,
    /// One of LMGC90's criteria with tolerance tol.
    Lmgc(Criterion),
}

/// Options of `solve-fc`.
#[derive(Clone, Debug, PartialEq)]
pub struct FcOptions {
    pub tol: f64,
    pub max_sweeps: u32,
    pub check_every: u32,
    pub norm: FcNorm,
}

/// Result of `solve-fc`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FcSolution {
    pub r: Vec<f64>,
    pub u: Vec<f64>,
    pub sweeps: u32,
    pub converged: bool,
    /// ‖F(r)‖/‖q‖ at the end.
    pub residual: f64,
    pub solve_seconds: f64,
}

/// Reads and solves one problem file.
pub fn solve_file(path: &Path, _opts: &FcOptions) -> Result<FcSolution, InputError> {
    Err(InputError { file: path.display().to_string(), line: None, key: String::new(), message: "not implemented yet".into() })
}
