//! # nscdd: non-smooth contact dynamics with domain decomposition
//!
//! The framework holds what every body family shares, written once for 2D and 3D
//! over the dimension trait [`dim::Dim`]: bodies and contacts ([`model`]), the
//! Moreau–Jean time step ([`engine`], [`step`]), contact detection driven by plugins' narrow phases ([`detect`],
//! [`registry`]), contact laws ([`law`]), the NLGS solver and LMGC90's convergence
//! norms ([`solver::nlgs`], [`norms`]), body families beside the rigid bodies
//! ([`family`], glued by [`dd`]), scene files ([`scene`]), outputs
//! ([`output`]) and frictional-contact problems in local form ([`fc`]).
//! It never names a plugin: shapes, detectors and generators come from plugins
//! through the [`registry::Registry`].
//!
//! ```no_run
//! use nscdd::registry::Registry;
//! # fn plugins(_: &mut Registry) {}
//! let mut reg = Registry::new();
//! plugins(&mut reg); // e.g. reg.add_plugin(&nscdd_rigid_disks::RigidDisks)
//! let mut scene = nscdd::scene::load("scene.toml".as_ref(), &reg).unwrap();
//! for _ in 0..scene.world.time.steps {
//!     let report = scene.world.step().unwrap();
//!     if !report.solve.converged { eprintln!("step {} did not converge", scene.world.step); }
//! }
//! ```

pub use error::Error;

pub mod dd;
pub mod detect;
pub mod dim;
pub mod drive;
pub mod engine;
pub mod error;
pub mod family;
pub mod fc;
pub mod law;
pub mod limits;
pub mod model;
pub mod norms;
pub mod output;
pub mod params;
pub mod plugin;
pub mod registry;
pub mod run;
pub mod scene;
pub mod shape;
pub mod solver;
pub mod step;
pub mod world;
