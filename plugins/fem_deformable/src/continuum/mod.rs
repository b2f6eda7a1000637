//! # Continuum regions glued to grains (docs/CONTINUUM.md)
//!
//! A `[[continuum]]` entry is a finite-element region standing for a granular
//! medium at the scale of its mean fields (a homogenized material), overlapping
//! the grains in a band where both models coexist:
//!
//! ```toml
//! [[continuum]]
//! name = "ground"                # optional
//! material = "ground"            # a [[materials]] name: the homogenized density ρ
//! young = 5e7                    # E (Pa) and ν of the homogenized medium
//! poisson = 0.25
//! fix = ["bottom"]
//! mesh = { rectangle = { origin = [0.0, -0.5], size = [1.0, 0.7], cells = [20, 14] } }
//! band = { normal = [0.0, 1.0], continuum = 0.0, discrete = 0.2 }
//! ```
//!
//! (every key of `[[deformable]]`, and `band`). Along the band's
//! unit `normal`, s = n·x: the continuum's weight is α(x) = 1 where s is on the
//! `continuum` side of the band, 0 on the `discrete` side, linear between. M and K
//! are weighted by α cell by cell (at the cell's centroid); a grain whose centre
//! lies in the mesh where α > 0 is **tied** to the continuum's material point under
//! it (v_p − N(ξ_p)V = 0, one multiplier per grain, [`ties`]) and keeps the share
//! w_p = 1 − α(x_p) of its mass (its rotation stays free, with its whole inertia).
//! The ties are the family's contacts in the NSCDD stage ([`family`]).

pub mod band;
pub mod family;
pub mod initial;
pub mod plastic;
pub mod scene;
pub mod sides;
pub mod ties;

pub use family::Continuum;

use nscdd::dim::{D2, D3};

/// The scene section of continuum regions.
pub const SECTION: &str = "continuum";

/// 2D continuum regions.
pub type Continuum2 = Continuum<D2, 2>;
/// 3D continuum regions.
pub type Continuum3 = Continuum<D3, 3>;
