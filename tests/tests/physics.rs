//! Physics validation: the engine's numbers against analytic answers.
//!
//! Each test states the analytic result, how it is measured, and why its tolerance
//! is what it is. Run with
//! `cargo test --release -p nscdd-tests --test physics -- --nocapture` to see every
//! measured number beside its expected value.
//!
//! - [`incline`]: a block and a free disk on an incline (stick/slip thresholds
//!   tan α = μ and μ = tan α / 3, accelerations, impulses);
//! - [`stacks`]: a column of disks (force under the k-th disk = k m g) and a
//!   three-disk pyramid (friction threshold 2 − √3, statics' forces);
//! - [`impacts`]: Newton's cradle (Moreau's simultaneous impact law) and a
//!   bouncing ball (rest time, energy conservation with θ = ½, e = 1);
//! - [`pressure`]: a pressure drive on a wall of a 2D box sample (wall force σ H);
//! - [`determinism`]: bitwise-identical reruns;
//! - [`compliant`]: the `compliant` law against a mass on a spring (static sink
//!   m g / k, contact time π √(m/k), restitution of a damping ratio, the chain's
//!   wave speed).

mod common;

#[path = "physics/incline.rs"]
mod incline;

#[path = "physics/stacks.rs"]
mod stacks;

#[path = "physics/impacts.rs"]
mod impacts;

#[path = "physics/determinism.rs"]
mod determinism;

#[path = "physics/pressure.rs"]
mod pressure;

#[path = "physics/plugin_law.rs"]
mod plugin_law;

#[path = "physics/compliant.rs"]
mod compliant;
