//! Example scenes of nscdd, in `examples/scenes/`:
//!
//! - `deposit.toml`: 1000 polydisperse disks deposited in a box under gravity;
//! - `biaxial.toml`: a 2000-disk biaxial test: isotropic compaction by stress-driven
//!   walls, then the top wall driven at constant velocity under constant lateral
//!   pressure; `history.csv` holds ε1, sin φ and the solid fraction ν;
//! - `triaxial3d.toml`: 1000 polydisperse spheres compacted isotropically by
//!   pressure-driven walls, then loaded at a constant axial strain rate under
//!   constant lateral pressure; `history.csv` holds q/p, the solid fraction and the
//!   coordination number against ε1 (`scripts/triaxial_plot.py` plots them).
//!
//! Run one with `cargo run --release -- run examples/scenes/deposit.toml --out out/deposit`.

/// Paths of the example scenes, relative to the repository root.
pub const SCENES: &[&str] = &["examples/scenes/deposit.toml", "examples/scenes/biaxial.toml"];

/// The 3D example scenes.
pub const SCENES_3D: &[&str] = &["examples/scenes/triaxial3d.toml"];
