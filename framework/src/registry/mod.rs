//! The plugin registry: what plugins add to the framework.
//!
//! A [`Plugin`] registers, by name, shape kinds (each with its own struct-of-arrays
//! store), pair detectors keyed by the pair of shape kinds, body generators, contact
//! laws, writers and body families ([`crate::family`]: a scene section of their own).
//! The framework names no plugin: scenes refer to these names, and
//! [`crate::scene`] resolves them once at load time; a pair of shape kinds that can
//! meet in a scene but has no detector is an error then. After setup the time loop
//! holds concrete data; detectors are called once per batch of candidate pairs, never
//! per contact inside the solver.
//!
//! ```
//! use nscdd::registry::{Plugin, Registry};
//! struct Nothing;
//! impl Plugin for Nothing {
//!     fn name(&self) -> &'static str { "nothing" }
//!     fn build(&self, _reg: &mut Registry) {}
//! }
//! let mut reg = Registry::new();
//! reg.add_plugin(&Nothing);
//! assert!(reg.plugins().contains(&"nothing"));
//! ```

use crate::dim::{Dim, D2, D3};
use crate::family::FamilyKind;
use crate::law::LawDef;
pub mod builder;
pub mod guard;
mod guard_family;
pub use crate::limits;

pub use crate::output::Writer;
pub use crate::shape::*;
use builder::SceneBuilder;
use std::any::Any;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Makes bodies from parameters (`[[generate]]` sections of a scene).
pub trait Generator<D: Dim>: Send + Sync {
    fn generate(&self, params: &toml::Table, out: &mut SceneBuilder<'_, D>) -> Result<(), ParamError>;
}

/// The plugin interface, after bevy's `Plugin`: add what you provide to the registry.
pub trait Plugin {
    fn name(&self) -> &'static str;
    fn build(&self, reg: &mut Registry);
}

/// What plugins provide for one dimension: shape kinds, pair detectors keyed by
/// the pair of kinds, generators.
/// Makes a shape kind's empty store (its plugin's code: guarded when the plugin was
/// loaded at run time, [`guard`]).
pub type NewStore<D> = Arc<dyn Fn() -> Box<dyn ShapeStore<D>> + Send + Sync>;

/// Makes a writer (its plugin's code: guarded when loaded at run time).
pub type NewWriter<D> = Arc<dyn Fn() -> Box<dyn Writer<D>> + Send + Sync>;

/// A law kind as registered: its definition and its parser (guarded when its plugin
/// was loaded at run time, [`guard`]).
pub struct LawKind {
    pub def: LawDef,
    pub parse: Arc<dyn Fn(&toml::Table) -> Result<Arc<dyn crate::law::Law>, ParamError> + Send + Sync>,
}

pub struct Tables<D: Dim> {
    pub(crate) shapes: BTreeMap<&'static str, NewStore<D>>,
    pub(crate) detectors: BTreeMap<(&'static str, &'static str), Arc<dyn PairDetector<D>>>,
    pub(crate) generators: BTreeMap<&'static str, Box<dyn Generator<D>>>,
    pub(crate) writers: BTreeMap<&'static str, NewWriter<D>>,
    pub(crate) families: BTreeMap<&'static str, Box<dyn FamilyKind<D>>>,
}

impl<D: Dim> Default for Tables<D> {
    fn default() -> Self {
        Tables {
            shapes: BTreeMap::new(),
            detectors: BTreeMap::new(),
            generators: BTreeMap::new(),
            writers: BTreeMap::new(),
            families: BTreeMap::new(),
        }
    }
}

/// Everything plugins provide, by name.
#[derive(Default)]
pub struct Registry {
    plugins: Vec<&'static str>,
    /// What each plugin added ([`Self::contents`] after less before), by plugin.
    added: Vec<Vec<String>>,
    pub(crate) laws: BTreeMap<&'static str, LawKind>,
    t2: Tables<D2>,
    t3: Tables<D3>,
    /// Memory a scene may use (bytes); `None`: the machine's available memory.
    max_memory: Option<f64>,
    /// Set by the plugin loader while a run-time plugin registers: what it adds is
    /// wrapped in this guard ([`guard`]).
    pub(crate) guard: Option<guard::Guard>,
}

impl Registry {
    /// A registry holding the framework's own laws and writers.
    pub fn new() -> Self {
        let mut r = Registry::default();
        for def in crate::law::builtin() {
            r.add_law(def);
        }
        r.add_writer::<D2>("vtk", || Box::<crate::output::vtk::VtkWriter>::default());
        r.add_writer::<D3>("vtk", || Box::<crate::output::vtk::VtkWriter>::default());
        r
    }
    /// The memory a scene may use (bytes), checked by generators before they
    /// allocate ([`limits`]); by default the machine's available memory.
    pub fn set_max_memory(&mut self, bytes: f64) {
        self.max_memory = Some(bytes);
    }
    pub fn max_memory(&self) -> Option<f64> {
        self.max_memory
    }
    pub fn add_plugin(&mut self, p: &dyn Plugin) -> &mut Self {
        let before = self.contents();
        self.plugins.push(p.name());
        p.build(self);
        let after = self.contents();
        self.added.push(after.into_iter().filter(|x| !before.contains(x)).collect());
        self
    }
    pub fn plugins(&self) -> Vec<&'static str> {
        self.plugins.clone()
    }
    /// Each plugin with what it registered (`shape 2D polygon`, `detector 2D
    /// polygon–disk`, `law mohr_coulomb`, …), in the order they were added.
    pub fn plugin_contents(&self) -> Vec<(&'static str, Vec<String>)> {
        self.plugins.iter().copied().zip(self.added.iter().cloned()).collect()
    }
    /// Everything registered, one line per item (`nscdd plugins`).
    pub fn contents(&self) -> Vec<String> {
        let mut out: Vec<String> = self.laws.keys().map(|l| format!("law {l}")).collect();
        fn of<D: Dim>(t: &Tables<D>, out: &mut Vec<String>) {
            let d = D::NAME;
            out.extend(t.shapes.keys().map(|k| format!("shape {d} {k}")));
            out.extend(t.detectors.keys().map(|(a, b)| format!("detector {d} {a}–{b}")));
            out.extend(t.generators.keys().map(|k| format!("generator {d} {k}")));
            out.extend(t.writers.keys().map(|k| format!("writer {d} {k}")));
            out.extend(t.families.keys().map(|k| format!("body family {d} [[{k}]]")));
        }
        of(&self.t2, &mut out);
        of(&self.t3, &mut out);
        out
    }
    /// The tables of dimension D.
    pub fn tables<D: Dim>(&self) -> &Tables<D> {
        let t: &dyn Any = if D::N == 2 { &self.t2 } else { &self.t3 };
        t.downcast_ref().expect("Dim is sealed: D2 or D3")
    }
    fn tables_mut<D: Dim>(&mut self) -> &mut Tables<D> {
        let t: &mut dyn Any = if D::N == 2 { &mut self.t2 } else { &mut self.t3 };
        t.downcast_mut().expect("Dim is sealed: D2 or D3")
    }
    pub fn add_shape<D: Dim>(&mut self, def: ShapeKindDef<D>) {
        let new_store = def.new_store;
        let make: NewStore<D> = match self.guard.clone() {
            None => Arc::new(new_store),
            Some(guard) => Arc::new(move || {
                let inner = guard.call(new_store);
                Box::new(guard::GuardedStore {
                    inner,
                    guard: guard.clone(),
                }) as Box<dyn ShapeStore<D>>
            }),
        };
        self.tables_mut::<D>().shapes.insert(def.name, make);
    }
    pub fn add_detector<D: Dim>(&mut self, a: &'static str, b: &'static str, d: Arc<dyn PairDetector<D>>) {
        let d = match self.guard.clone() {
            None => d,
            Some(guard) => Arc::new(guard::GuardedDetector { inner: d, guard }),
        };
        self.tables_mut::<D>().detectors.insert((a, b), d);
    }
    pub fn add_generator<D: Dim>(&mut self, name: &'static str, g: Box<dyn Generator<D>>) {
        let g = match self.guard.clone() {
            None => g,
            Some(guard) => Box::new(guard::GuardedGenerator { inner: g, guard }),
        };
        self.tables_mut::<D>().generators.insert(name, g);
    }
    pub fn add_law(&mut self, def: LawDef) {
        let p = def.parse;
        let parse: Arc<dyn Fn(&toml::Table) -> Result<Arc<dyn crate::law::Law>, ParamError> + Send + Sync> = match self.guard.clone() {
            None => Arc::new(p),
            Some(guard) => Arc::new(move |t: &toml::Table| {
                let inner = guard.call(|| p(t))?;
                Ok(Arc::new(guard::GuardedLaw {
                    inner,
                    guard: guard::GuardDebug(guard.clone()),
                }) as Arc<dyn crate::law::Law>)
            }),
        };
        self.laws.insert(def.name, LawKind { def, parse });
    }
    pub fn add_writer<D: Dim>(&mut self, name: &'static str, make: fn() -> Box<dyn Writer<D>>) {
        let make: NewWriter<D> = match self.guard.clone() {
            None => Arc::new(make),
            Some(guard) => Arc::new(move || {
                let inner = guard.call(make);
                Box::new(guard::GuardedWriter {
                    inner,
                    guard: guard.clone(),
                }) as Box<dyn Writer<D>>
            }),
        };
        self.tables_mut::<D>().writers.insert(name, make);
    }
    /// A body family ([`crate::family`]) whose entries are the scene section `section`
    /// (`[[section]]`) of a scene of dimension D.
    pub fn add_family<D: Dim>(&mut self, section: &'static str, kind: Box<dyn FamilyKind<D>>) {
        let kind: Box<dyn FamilyKind<D>> = match self.guard.clone() {
            None => kind,
            Some(guard) => Box::new(guard_family::GuardedFamilyKind { inner: kind, guard }),
        };
        self.tables_mut::<D>().families.insert(section, kind);
    }
    /// The body family of a scene section.
    pub fn family<D: Dim>(&self, section: &str) -> Option<&dyn FamilyKind<D>> {
        self.tables::<D>().families.get(section).map(|b| &**b)
    }
    /// The scene sections of the body families of dimension D.
    pub fn family_sections<D: Dim>(&self) -> Vec<&'static str> {
        self.tables::<D>().families.keys().copied().collect()
    }
    /// A writer's constructor by name.
    pub fn writer<D: Dim>(&self, name: &str) -> Option<NewWriter<D>> {
        self.tables::<D>().writers.get(name).cloned()
    }
    /// The shape kinds of dimension D.
    pub fn shape_kinds<D: Dim>(&self) -> Vec<&'static str> {
        self.tables::<D>().shapes.keys().copied().collect()
    }
    pub fn generator_names<D: Dim>(&self) -> Vec<&'static str> {
        self.tables::<D>().generators.keys().copied().collect()
    }
    pub fn law_names(&self) -> Vec<&'static str> {
        self.laws.keys().copied().collect()
    }
    /// The detector for a pair of kinds, and whether the registered order is (b, a).
    pub fn detector<D: Dim>(&self, a: &str, b: &str) -> Option<(Arc<dyn PairDetector<D>>, bool)> {
        let d = &self.tables::<D>().detectors;
        if let Some((_, d)) = d.iter().find(|((x, y), _)| *x == a && *y == b) {
            return Some((d.clone(), false));
        }
        d.iter().find(|((x, y), _)| *x == b && *y == a).map(|(_, d)| (d.clone(), true))
    }
}
