//! Panics in a run-time plugin's code, caught where they happen.
//!
//! A plugin library holds its own copy of Rust's standard library: a panic raised
//! in its code cannot be caught by the host's `catch_unwind` (the host's runtime
//! aborts on a panic of another runtime). So what a plugin registers is wrapped,
//! *by the plugin's copy of the registry* while the plugin registers, in a guard
//! whose `catch_unwind` is the plugin's: a panic is caught there and raised again
//! in the host by the host's function [`Guard::raise`] (a [`PluginPanic`] naming
//! the plugin), which the host's program reports (`plugin NAME: …`). Built-in
//! plugins are not wrapped (the registry's guard is unset for them).
//!
//! Wrapped: pair detectors, generators, shape stores (every method, defaults
//! included, so that the store's own overrides still answer), contact laws,
//! writers, and body families ([`super::guard_family`]).

use super::{Generator, ParamError, SceneBuilder};
use crate::dim::Dim;
use crate::shape::*;
use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Mutex;

/// A plugin's panic raised again in the host: "plugin NAME: message at file:line".
#[derive(Debug)]
pub struct PluginPanic(pub String);

/// How a plugin's guard reports a caught panic to the host (set by the host's loader).
#[derive(Clone)]
pub struct Guard {
    /// The plugin's crate name (a string of the host, kept for the process).
    pub plugin: String,
    /// The host's function: raises a [`PluginPanic`] with the host's runtime.
    pub raise: fn(String) -> !,
}

/// Where the plugin's last panic happened (this copy of the framework: in a plugin,
/// the plugin's), recorded by [`silence_and_locate`]'s hook.
static WHERE: Mutex<Option<String>> = Mutex::new(None);

/// In a plugin: its runtime's panic hook records the location instead of printing
/// (the host reports the panic).
pub fn silence_and_locate() {
    std::panic::set_hook(Box::new(|info| {
        if let (Ok(mut w), Some(l)) = (WHERE.lock(), info.location()) {
            *w = Some(format!(" at {}:{}", l.file(), l.line()));
        }
    }));
}

impl Guard {
    /// `f()`, a panic caught and raised again in the host.
    #[inline]
    pub fn call<R>(&self, f: impl FnOnce() -> R) -> R {
        match catch_unwind(AssertUnwindSafe(f)) {
            Ok(r) => r,
            Err(e) => {
                let at = WHERE.lock().ok().and_then(|mut w| w.take()).unwrap_or_default();
                (self.raise)(format!("plugin {}: {}{at}", self.plugin, panic_text(&*e)))
            }
        }
    }
}

/// The message of a panic's payload.
pub fn panic_text(e: &(dyn Any + Send)) -> String {
    e.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| e.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic".into())
}

/// The host's [`Guard::raise`].
pub fn raise_in_host(message: String) -> ! {
    std::panic::panic_any(PluginPanic(message))
}

pub(crate) struct GuardedDetector<D: Dim> {
    pub inner: std::sync::Arc<dyn PairDetector<D>>,
    pub guard: Guard,
}

impl<D: Dim> PairDetector<D> for GuardedDetector<D> {
    fn detect(&self, ctx: &DetectCtx<'_, D>, pairs: &[[u32; 2]], out: &mut Vec<RawContact<D>>) {
        self.guard.call(|| self.inner.detect(ctx, pairs, out))
    }
}

pub(crate) struct GuardedGenerator<D: Dim> {
    pub inner: Box<dyn Generator<D>>,
    pub guard: Guard,
}

impl<D: Dim> Generator<D> for GuardedGenerator<D> {
    fn generate(&self, params: &toml::Table, out: &mut SceneBuilder<'_, D>) -> Result<(), ParamError> {
        self.guard.call(|| self.inner.generate(params, out))
    }
}

pub(crate) struct GuardedStore<D: Dim> {
    pub inner: Box<dyn ShapeStore<D>>,
    pub guard: Guard,
}

impl<D: Dim> ShapeStore<D> for GuardedStore<D> {
    fn kind(&self) -> &'static str {
        self.inner.kind()
    }
    fn len(&self) -> usize {
        self.inner.len()
    }
    fn is_empty(&self) -> bool {
        self.inner.is_empty()
    }
    fn as_any(&self) -> &dyn Any {
        self.inner.as_any()
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self.inner.as_any_mut()
    }
    fn push_params(&mut self, params: &toml::Table) -> Result<u32, ParamError> {
        let inner = &mut self.inner;
        self.guard.call(|| inner.push_params(params))
    }
    fn aabb(&self, s: u32, pos: D::Point, rot: D::Rot) -> Aabb<D> {
        self.guard.call(|| self.inner.aabb(s, pos, rot))
    }
    fn mass_properties(&self, s: u32, density: f64) -> MassProps<D> {
        self.guard.call(|| self.inner.mass_properties(s, density))
    }
    fn size(&self, s: u32) -> f64 {
        self.guard.call(|| self.inner.size(s))
    }
    fn glyph(&self, s: u32, pos: D::Point, rot: D::Rot) -> Glyph<D> {
        self.guard.call(|| self.inner.glyph(s, pos, rot))
    }
    fn describe(&self, s: u32) -> serde_json::Value {
        self.guard.call(|| self.inner.describe(s))
    }
    fn is_grain(&self) -> bool {
        self.inner.is_grain()
    }
    fn point_contact(&self, s: u32, pos: D::Point, rot: D::Rot, p: D::Point, hint: D::Point) -> Option<PointContact<D>> {
        self.guard.call(|| self.inner.point_contact(s, pos, rot, p, hint))
    }
    fn principal_frame(&self, s: u32) -> (D::Point, D::Rot) {
        self.guard.call(|| self.inner.principal_frame(s))
    }
    fn meets_faces(&self) -> bool {
        self.inner.meets_faces()
    }
    fn face_contact(&self, s: u32, pos: D::Point, rot: D::Rot, facet: &[D::Point]) -> Option<FaceContact<D>> {
        self.guard.call(|| self.inner.face_contact(s, pos, rot, facet))
    }
}

#[derive(Debug)]
pub(crate) struct GuardedLaw {
    pub inner: std::sync::Arc<dyn crate::law::Law>,
    pub guard: GuardDebug,
}

/// A [`Guard`] inside a `Debug` type.
#[derive(Clone)]
pub(crate) struct GuardDebug(pub Guard);

impl std::fmt::Debug for GuardDebug {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "guard of plugin {}", self.0.plugin)
    }
}

impl crate::law::Law for GuardedLaw {
    fn contacts(
        &self,
        step: &crate::law::LawStep,
        inputs: &[crate::law::LawInput],
        target: &mut [crate::model::Target],
        joint: &mut [crate::dim::joint::Joint],
    ) {
        self.guard.0.call(|| self.inner.contacts(step, inputs, target, joint))
    }
    fn contact(&self, step: &crate::law::LawStep, input: &crate::law::LawInput) -> crate::law::LawOutput {
        self.guard.0.call(|| self.inner.contact(step, input))
    }
    fn bonds(&self) -> bool {
        self.guard.0.call(|| self.inner.bonds())
    }
    fn compliance(&self, step: &crate::law::LawStep) -> f64 {
        self.guard.0.call(|| self.inner.compliance(step))
    }
}

pub(crate) struct GuardedWriter<D: Dim> {
    pub inner: Box<dyn crate::output::Writer<D>>,
    pub guard: Guard,
}

impl<D: Dim> crate::output::Writer<D> for GuardedWriter<D> {
    fn write(&mut self, world: &crate::world::World<D>, dir: &std::path::Path, frame: u32) -> std::io::Result<()> {
        let inner = &mut self.inner;
        self.guard.call(|| inner.write(world, dir, frame))
    }
    fn write_dd(
        &mut self,
        world: &crate::world::World<D>,
        dd: &crate::dd::DdView,
        dir: &std::path::Path,
        frame: u32,
    ) -> std::io::Result<()> {
        let inner = &mut self.inner;
        self.guard.call(|| inner.write_dd(world, dd, dir, frame))
    }
    fn finish(&mut self, dir: &std::path::Path) -> std::io::Result<()> {
        let inner = &mut self.inner;
        self.guard.call(|| inner.finish(dir))
    }
}
