//! Body families a plugin adds to scenes: finite-element bodies today, continuum
//! regions and researchers' families next. The framework names none of them.
//!
//! A plugin registers a [`FamilyKind`] under the name of a scene section
//! ([`crate::registry::Registry::add_family`]); the loader gives it the section's
//! `[[name]]` entries once the rigid world is built, and it returns the family
//! ([`SceneFamily`]): its bodies beside the world's rigid ones, solved by the one
//! NSCDD stage through the subdomain interface ([`crate::dd::Attached`]), stepped,
//! written, saved and restarted by the framework's run loop ([`crate::run`]).
//!
//! ```
//! use nscdd::family::{EntryError, FamilyContext, FamilyKind, SceneFamily};
//! use nscdd::dim::D2;
//! struct Nothing;
//! impl FamilyKind<D2> for Nothing {
//!     fn load(&self, entries: &[toml::Table], _: &FamilyContext<'_, D2>) -> Result<Box<dyn SceneFamily<D2>>, EntryError> {
//!         Err(EntryError { index: Some(0), key: "kind".into(), message: format!("{} entries, none built", entries.len()) })
//!     }
//! }
//! let mut reg = nscdd::registry::Registry::new();
//! reg.add_family::<D2>("nothing", Box::new(Nothing));
//! assert_eq!(reg.family_sections::<D2>(), vec!["nothing"]);
//! ```

use crate::dd::{Attached, DdStepReport, NscddOf, Rigid};
use crate::dim::Dim;
use crate::engine::{ContactStage, Diverged, StepReport};
use crate::world::World;
use std::any::Any;
use std::path::Path;

/// What a family's loader sees: the built rigid world (materials, gravity, h, θ,
/// alert distance) and the scene file's folder (files named in entries are relative
/// to it).
pub struct FamilyContext<'a, D: Dim> {
    pub world: &'a World<D>,
    pub dir: &'a Path,
    /// The registry's memory limit (`--max-memory`; None: the machine's), for
    /// [`Self::check_memory`].
    pub max_memory: Option<f64>,
    /// (this rank, ranks) when the scene is loaded for a run on several MPI ranks
    /// (`None`: one process). A family may then hold less at load: what only the
    /// ranks stepping one of its bodies need ([`Attached::solved_on`]) can be made
    /// when a rank first steps it.
    pub ranks: Option<(u32, u32)>,
}

impl<D: Dim> FamilyContext<'_, D> {
    /// Checks, before the family allocates, that `bytes` (its estimate of what it will
    /// hold, `what` says of what) fit beside the rigid world in the memory limit
    /// ([`crate::registry::limits`]); Err: the message with the estimate and the limit.
    pub fn check_memory(&self, bytes: f64, what: &str) -> Result<(), String> {
        let need = bytes.max(0.0) + self.world.bodies.len() as f64 * crate::limits::bytes_per_body::<D>();
        crate::limits::check(need, self.max_memory, what).map_err(|m| format!("{m}; make it smaller"))
    }
}

/// A bad entry of a family's section: `[[section]]` entry `index` (none: the section
/// as a whole), its `key` (empty: the entry), the message. The loader adds the file
/// and the line.
#[derive(Clone, Debug, PartialEq)]
pub struct EntryError {
    pub index: Option<usize>,
    pub key: String,
    pub message: String,
}

/// Builds a family from the entries of its scene section.
pub trait FamilyKind<D: Dim>: Send + Sync {
    fn load(&self, entries: &[toml::Table], cx: &FamilyContext<'_, D>) -> Result<Box<dyn SceneFamily<D>>, EntryError>;
    /// On MPI ranks, before any world body is built (`cx.world` holds none): boxes
    /// `[lo, hi]` (z = 0 in 2D) holding every point at which [`Self::load`] reads
    /// a world body and at which the loaded family's first
    /// [`Attached::held_everywhere`] and [`Attached::reach`] may name one. Each rank
    /// then builds only its part of the world ([`crate::scene::part`]): its halo and
    /// every body whose box, grown by the alert distance, meets one of these, and
    /// the family is loaded against that part; its load must then find world
    /// bodies by slot ([`crate::model::BodyIds`]). On a restart, `saved` is the
    /// family's saved state ([`SceneFamily::save_state`]) and the boxes must also
    /// hold its first step's reach at that state (a state it cannot read: `None`,
    /// the restart then loads whole and reports the error). `None` (the default):
    /// the scene is loaded whole on every rank, each rank keeping its part before
    /// the first step.
    fn load_boxes(
        &self,
        _entries: &[toml::Table],
        _cx: &FamilyContext<'_, D>,
        _saved: Option<&serde_json::Value>,
    ) -> Result<Option<Vec<[[f64; 3]; 2]>>, EntryError> {
        Ok(None)
    }
}

/// A body family of a loaded scene (module docs). Beside the subdomain interface
/// ([`Attached`]), what the run loop needs: the step's end, outputs, saved state.
pub trait SceneFamily<D: Dim>: Attached<Rigid<D>> + Any + Send {
    /// The scene section the family came from (its key in `final.json`).
    fn section(&self) -> &'static str;
    /// One line for `nscdd check` ("2 deformable bodies, 1 200 nodes").
    fn describe(&self) -> String;
    /// The family's own one-domain contact stage, if it has one (the solve of all the
    /// world's and the family's contacts together); without it, a scene without a
    /// decomposition is solved by NSCDD on one subdomain, which is the same NLGS.
    fn one_domain(&mut self) -> Option<&mut dyn ContactStage<World<D>>> {
        None
    }
    /// Once after the scene is loaded, before any step (and before a restart's state
    /// is read): the family may change the world bodies it shares with its own (the
    /// continuum family gives each grain of its overlap band its share of the mass).
    fn share_world(&mut self, _w: &mut World<D>) {}
    /// The end of a step, after the world's positions: the family's own (u⁺ = u⁻ +
    /// h((1 − θ)V⁻ + θV⁺)); a failure is a divergence naming the step.
    fn update(&mut self, w: &World<D>) -> Result<(), Diverged>;
    /// The family's contacts of the last step.
    fn contacts(&self) -> usize;
    /// Extra `history.csv` columns, and their values after a step.
    fn history_columns(&self) -> Vec<String> {
        vec![]
    }
    fn history_values(&self, _out: &mut Vec<f64>) {}
    /// A VTK frame (with `output.vtk`) at time `t`; `finish` at the end of the run.
    fn write_frame(&mut self, _dir: &Path, _frame: u32, _t: f64) -> std::io::Result<()> {
        Ok(())
    }
    fn finish(&mut self, _dir: &Path) -> std::io::Result<()> {
        Ok(())
    }
    /// The family's state: under its section in `final.json` and checkpoints, read
    /// back by [`Self::load_state`] (every number that the next step uses, so that a
    /// restart continues bitwise).
    fn save_state(&self) -> serde_json::Value;
    /// The family's share of the last step's local problem (`nscdd export-fc`):
    /// q, μ, its contacts' H_bᵀ on the world's rigid bodies and its W blocks
    /// ([`crate::fc::FamilyShare`]); `None`: the family cannot give it (the export
    /// is refused).
    fn local_problem(&self, _w: &World<D>) -> Option<crate::fc::FamilyShare> {
        None
    }
    fn load_state(&mut self, state: &serde_json::Value) -> Result<(), String>;
    fn as_any(&self) -> &dyn Any;
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

/// Whether a scene with `families` and the `decomposition` given needs an NSCDD
/// solver: a decomposition, or families without one one-domain stage of their own.
pub fn needs_nscdd<D: Dim>(decomposed: bool, families: &mut [Box<dyn SceneFamily<D>>]) -> bool {
    decomposed
        || match families {
            [] => false,
            [one] => one.one_domain().is_none(),
            _ => true,
        }
}

/// One time step of the world and its families: contacts solved by `dd` (NSCDD) when
/// given, else by the single family's one-domain stage or, without families, NLGS;
/// then the families' [`SceneFamily::update`]. The second value is NSCDD's report.
pub fn step<D: Dim>(
    w: &mut World<D>,
    families: &mut [&mut dyn SceneFamily<D>],
    dd: Option<&mut NscddOf<Rigid<D>>>,
) -> Result<(StepReport, Option<DdStepReport>), Diverged> {
    let stepped = match dd {
        Some(n) => {
            let mut fams: Vec<&mut dyn Attached<Rigid<D>>> = families.iter_mut().map(|f| &mut **f as &mut dyn Attached<Rigid<D>>).collect();
            let r = n.step_families(w, &mut fams)?;
            let plain = StepReport {
                solve: r.solve,
                contacts: r.contacts,
                times: r.times,
            };
            (plain, Some(r))
        }
        None => match families.first_mut().and_then(|f| f.one_domain()) {
            Some(stage) => (w.step_with(stage)?, None),
            None => (w.step()?, None),
        },
    };
    for f in families.iter_mut() {
        f.update(w)?;
    }
    Ok(stepped)
}

/// The local problem of the last step of `w` and its families (`nscdd export-fc`):
/// the world's contacts, then each family's. Err: a family that cannot give its
/// share (named).
pub fn local_problem<D: Dim>(w: &World<D>, families: &[Box<dyn SceneFamily<D>>]) -> Result<crate::fc::FcProblem, String> {
    let mut shares = vec![];
    for f in families {
        let share = f
            .local_problem(w)
            .ok_or_else(|| format!("the `{}` family cannot give its contacts' local problem", f.section()))?;
        shares.push(share);
    }
    Ok(crate::fc::problem_of(w, &shares))
}

/// The world bodies the families read or touch, for MPI ranks
/// ([`crate::dd::attach::touched`]: every rank steps them); `None` if a family may
/// touch any world body (its scene then holds every body on every rank).
pub fn touched<D: Dim>(w: &World<D>, families: &[Box<dyn SceneFamily<D>>]) -> Option<crate::dd::attach::Touched> {
    let fams: Vec<&dyn Attached<Rigid<D>>> = families.iter().map(|f| &**f as &dyn Attached<Rigid<D>>).collect();
    crate::dd::attach::touched(w, &fams)
}

/// The families' states, by section, for `final.json` and checkpoints.
pub fn states<D: Dim>(families: &[Box<dyn SceneFamily<D>>]) -> serde_json::Map<String, serde_json::Value> {
    families.iter().map(|f| (f.section().to_string(), f.save_state())).collect()
}
