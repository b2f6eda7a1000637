//! Example scenes of nscdd, in `examples/scenes/`:
//!
//! - `deposit.toml`: 1000 polydisperse disks deposited in a box under gravity;
//! - `biaxial.toml`: a 2000-disk biaxial test: isotropic compaction by stress-driven
//!   walls, then the top wall driven at constant velocity under constant lateral
//!   pressure; `history.csv` holds ε1, sin φ and the solid fraction ν.
//!
//! Run one with `cargo run --release -- run examples/scenes/deposit.toml --out out/deposit`.

/// Paths of the example scenes, relative to the repository root.
pub const SCENES: &[&str] = &["examples/scenes/deposit.toml", "examples/scenes/biaxial.toml"];
