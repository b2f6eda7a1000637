//! Plugins loaded at run time: shared libraries (`cdylib`) that register shapes,
//! detectors, laws, generators, writers and body families into the host's
//! [`Registry`] (docs/PLUGINS.md).
//!
//! **The boundary.** Rust has no stable ABI, so a plugin and the host must be built
//! from the same framework source by the same compiler with the same dependency
//! versions and features; then every Rust type has the same layout on both sides and
//! trait objects cross as they are (no wrapper, no per-call cost). That is checked
//! before any Rust type crosses: the library exports one C-ABI function,
//! `nscdd_plugin_entry`, made by [`export_plugin!`], which returns a `#[repr(C)]`
//! [`PluginEntry`] whose first field is the interface version [`ABI_VERSION`]; the
//! host reads that field alone first, then compares the build fingerprint — the
//! framework's version, the compiler's version, the framework's features and an
//! interface hash (the `TypeId`s of the types that cross: equal only for the same
//! compilation of the same framework source, dependencies and features) — and only
//! then calls the plugin's registration, under `catch_unwind`. A mismatch, a missing
//! or corrupt library or a panic while registering is an `Err` naming the library
//! and what differs. (`abi_stable` was the other way: every interface rewritten in
//! its FFI-safe types, nalgebra's included, and a call through its vtables per
//! use; the fingerprint keeps the framework's own traits and costs nothing per call.)
//!
//! Loaded libraries are never unloaded (their code may run until the process ends).
//! A panic inside a plugin's code is caught by the plugin's own runtime in a guard
//! around what it registered and raised again in the host naming the plugin
//! ([`crate::registry::guard`]); the CLI reports it as `plugin NAME: …` and stops,
//! keeping what was written.
//! A plugin must not declare a `#[global_allocator]`: host and plugins free each
//! other's allocations (both use the system allocator).
//!
//! ```no_run
//! // in the plugin crate (crate-type = ["cdylib"]):
//! struct MyPlugin;
//! impl nscdd::registry::Plugin for MyPlugin {
//!     fn name(&self) -> &'static str { "my_plugin" }
//!     fn build(&self, _reg: &mut nscdd::registry::Registry) { /* reg.add_shape(…) */ }
//! }
//! nscdd::export_plugin!(MyPlugin);
//! // in the host:
//! let mut reg = nscdd::registry::Registry::new();
//! nscdd::plugin::load(std::path::Path::new("target/release/libmy_plugin.so"), &mut reg).unwrap();
//! ```

use crate::dim::{D2, D3};
use crate::registry::{PairDetector, Plugin, Registry, ShapeStore};
use std::any::TypeId;
use std::ffi::{c_char, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The version of the plugin interface: raised whenever [`PluginEntry`] or the
/// meaning of its fields changes.
pub const ABI_VERSION: u32 = 1;

/// The framework's version.
pub const NSCDD_VERSION: &str = env!("CARGO_PKG_VERSION");

/// The compiler that built this copy of the framework (`rustc -V`).
pub const RUSTC_VERSION: &str = env!("NSCDD_RUSTC_VERSION");

/// What `nscdd_plugin_entry` returns (a static of the plugin). `abi` comes first and
/// is read alone before anything else.
#[repr(C)]
pub struct PluginEntry {
    pub abi: u32,
    /// `size_of::<PluginEntry>()` in the plugin.
    pub size: u32,
    /// [`interface_hash`] of the plugin's copy of the framework.
    pub interface: u64,
    /// NUL-terminated: the framework's version, the compiler's, the framework's
    /// features, the plugin's crate name.
    pub nscdd_version: *const c_char,
    pub rustc: *const c_char,
    pub features: *const c_char,
    pub name: *const c_char,
    /// Registers the plugin into the `Registry` behind the pointer; null, or the
    /// message of a panic while registering.
    pub register: unsafe extern "C" fn(*mut c_void) -> *const c_char,
}

struct Entry(PluginEntry);
// SAFETY: the entry holds pointers to static, immutable strings and a function.
unsafe impl Sync for Entry {}
unsafe impl Send for Entry {}

/// The framework's features that change the types crossing the boundary.
pub fn features() -> &'static str {
    match (cfg!(feature = "mpi"), cfg!(feature = "hdf5")) {
        (false, false) => "\0",
        (true, false) => "mpi\0",
        (false, true) => "hdf5\0",
        (true, true) => "mpi,hdf5\0",
    }
}

/// A hash of the `TypeId`s of the types that cross the boundary: equal in the host and
/// a plugin only when both hold the same compilation of the framework.
pub fn interface_hash() -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    ABI_VERSION.hash(&mut h);
    for t in [
        TypeId::of::<Registry>(),
        TypeId::of::<crate::world::World2>(),
        TypeId::of::<crate::world::World3>(),
        TypeId::of::<dyn ShapeStore<D2>>(),
        TypeId::of::<dyn ShapeStore<D3>>(),
        TypeId::of::<dyn PairDetector<D2>>(),
        TypeId::of::<dyn PairDetector<D3>>(),
        TypeId::of::<dyn crate::law::Law>(),
        TypeId::of::<dyn crate::family::SceneFamily<D2>>(),
        TypeId::of::<dyn crate::family::SceneFamily<D3>>(),
        TypeId::of::<crate::scene::Scene<D2>>(),
        TypeId::of::<crate::scene::Scene<D3>>(),
    ] {
        t.hash(&mut h);
    }
    h.finish()
}

/// The plugin side of `nscdd_plugin_entry` ([`export_plugin!`]): the entry of this
/// copy of the framework, made once.
pub fn entry(name: &'static str, register: unsafe extern "C" fn(*mut c_void) -> *const c_char) -> *const PluginEntry {
    static ENTRY: std::sync::OnceLock<Entry> = std::sync::OnceLock::new();
    let e = ENTRY.get_or_init(|| {
        Entry(PluginEntry {
            abi: ABI_VERSION,
            size: std::mem::size_of::<PluginEntry>() as u32,
            interface: interface_hash(),
            nscdd_version: concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast(),
            rustc: concat!(env!("NSCDD_RUSTC_VERSION"), "\0").as_ptr().cast(),
            features: features().as_ptr().cast(),
            name: name.as_ptr().cast(),
            register,
        })
    });
    &e.0
}

/// The plugin side of the registration ([`export_plugin!`]): `plugin` built into the
/// registry behind `reg`, a panic caught and returned as its message.
///
/// # Safety
/// `reg` points to the host's `Registry`, of the same layout (the host checked the
/// fingerprint before calling).
pub unsafe fn register(reg: *mut c_void, plugin: &dyn Plugin) -> *const c_char {
    // SAFETY: the caller's contract
    let reg = unsafe { &mut *(reg as *mut Registry) };
    // this library's runtime: its panics are reported by the host (registry::guard)
    crate::registry::guard::silence_and_locate();
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        reg.add_plugin(plugin);
    })) {
        Ok(()) => std::ptr::null(),
        Err(e) => CString::new(panic_text(&*e).replace('\0', " ")).unwrap_or_default().into_raw(),
    }
}

pub use crate::registry::guard::panic_text;

/// Exports a plugin from a `cdylib` crate: `nscdd::export_plugin!(MyPlugin);` with
/// `MyPlugin` a unit value implementing [`Plugin`] (module docs).
#[macro_export]
macro_rules! export_plugin {
    ($plugin:expr) => {
        /// The plugin's entry point (nscdd's plugin interface).
        #[no_mangle]
        pub extern "C" fn nscdd_plugin_entry() -> *const $crate::plugin::PluginEntry {
            unsafe extern "C" fn register(reg: *mut ::std::ffi::c_void) -> *const ::std::ffi::c_char {
                // SAFETY: called by the host after its fingerprint check
                unsafe { $crate::plugin::register(reg, &$plugin) }
            }
            $crate::plugin::entry(concat!(env!("CARGO_CRATE_NAME"), "\0"), register)
        }
    };
}

/// A loaded plugin.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The plugin's crate name.
    pub crate_name: String,
    pub library: PathBuf,
    /// The names of the plugins it registered (`Plugin::name`).
    pub plugins: Vec<String>,
}

/// The libraries loaded so far (never unloaded) and their plugins.
/// A checked entry of a library that stays loaded (never unloaded: `'static`).
#[derive(Clone, Copy)]
struct Checked(&'static PluginEntry);
// SAFETY: the entry is immutable data and `extern "C"` functions of a library that
// is never unloaded
unsafe impl Send for Checked {}

static LOADED: Mutex<Vec<(Loaded, libloading::Library, Checked)>> = Mutex::new(Vec::new());

/// The plugins loaded so far.
pub fn loaded() -> Vec<Loaded> {
    LOADED.lock().map(|l| l.iter().map(|x| x.0.clone()).collect()).unwrap_or_default()
}

fn c_str(p: *const c_char) -> String {
    if p.is_null() {
        return String::new();
    }
    // SAFETY: a NUL-terminated static string of a plugin whose interface matched
    unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
}

/// Loads the plugin library at `path` into `reg` (module docs). Loading the same
/// library twice registers it once. Err: a message naming the library and what is
/// wrong (missing, not a library, not an nscdd plugin, built against another
/// interface, framework, compiler or features; a panic while registering).
pub fn load(path: &Path, reg: &mut Registry) -> Result<Loaded, String> {
    let shown = path.display();
    let full = std::fs::canonicalize(path).map_err(|e| format!("plugin library {shown}: {e}"))?;
    let known = LOADED
        .lock()
        .ok()
        .and_then(|all| all.iter().find(|p| p.0.library == full).map(|p| (p.0.clone(), p.2)));
    if let Some((l, checked)) = known {
        // loaded before (another registry, or named twice): register into this
        // registry unless it holds the plugin already
        if l.plugins.iter().all(|p| reg.plugins().contains(&p.as_str())) {
            return Ok(l);
        }
        register_into(checked.0, &l.crate_name, reg).map_err(|m| format!("plugin {} ({shown}): {m}", l.crate_name))?;
        return Ok(l);
    }
    // SAFETY: loading runs the library's initializers; an nscdd plugin has none of
    // its own (Rust runs no code before main), and a foreign library is refused below
    // before any of its functions is called
    let lib = unsafe { libloading::Library::new(&full) }.map_err(|e| format!("plugin library {shown}: cannot load it: {e}"))?;
    // SAFETY: the symbol's type is the one `export_plugin!` defines
    let entry = unsafe { lib.get::<extern "C" fn() -> *const PluginEntry>(b"nscdd_plugin_entry\0") }
        .map_err(|_| format!("plugin library {shown}: not an nscdd plugin (no `nscdd_plugin_entry`; see docs/PLUGINS.md)"))?;
    let e = entry();
    if e.is_null() {
        return Err(format!("plugin library {shown}: its entry point returned nothing"));
    }
    // SAFETY: every version of the interface starts with `abi: u32`
    let abi = unsafe { *(e as *const u32) };
    if abi != ABI_VERSION {
        return Err(format!(
            "plugin library {shown}: built for plugin interface version {abi}, this nscdd has version {ABI_VERSION}: rebuild the plugin against this nscdd"
        ));
    }
    // SAFETY: same interface version, same layout of the entry
    let e = unsafe { &*e };
    let mut differs = vec![];
    let (v, rc, ft) = (c_str(e.nscdd_version), c_str(e.rustc), c_str(e.features));
    if v != NSCDD_VERSION {
        differs.push(format!("nscdd {v} (this program: {NSCDD_VERSION})"));
    }
    if rc != RUSTC_VERSION {
        differs.push(format!("compiler `{rc}` (this program: `{RUSTC_VERSION}`)"));
    }
    let host_ft = features().trim_end_matches('\0');
    if ft != host_ft {
        differs.push(format!("framework features [{ft}] (this program: [{host_ft}])"));
    }
    if e.size as usize != std::mem::size_of::<PluginEntry>() || (differs.is_empty() && e.interface != interface_hash()) {
        differs.push("another build of the framework (dependency versions or build profile)".into());
    }
    if !differs.is_empty() {
        return Err(format!(
            "plugin library {shown}: built against {}; build the plugin in the nscdd workspace with the same cargo command and features as nscdd (docs/PLUGINS.md)",
            differs.join(", ")
        ));
    }
    let name = c_str(e.name);
    let before = reg.plugins().len();
    register_into(e, &name, reg).map_err(|m| format!("plugin {name} ({shown}): {m}"))?;
    let l = Loaded {
        crate_name: name,
        library: full,
        plugins: reg.plugins()[before..].iter().map(|p| p.to_string()).collect(),
    };
    if let Ok(mut all) = LOADED.lock() {
        all.push((l.clone(), lib, Checked(e)));
    } else {
        // never unloaded, even when the list is poisoned
        std::mem::forget(lib);
    }
    Ok(l)
}

/// Runs a checked plugin's registration into `reg`, guarded
/// ([`crate::registry::guard`]).
fn register_into(e: &PluginEntry, name: &str, reg: &mut Registry) -> Result<(), String> {
    reg.guard = Some(crate::registry::guard::Guard {
        plugin: name.to_string(),
        raise: crate::registry::guard::raise_in_host,
    });
    // SAFETY: the fingerprint matched: the plugin's Registry is ours
    let err = unsafe { (e.register)(reg as *mut Registry as *mut c_void) };
    reg.guard = None;
    if !err.is_null() {
        return Err(format!("panicked while registering: {}", c_str(err)));
    }
    Ok(())
}

/// The plugins a scene's text names (`[[plugins]]`, relative to the scene's folder),
/// loaded into `reg` ([`crate::scene::load_plugins`]); errors name the entry's line.
pub fn load_for_scene(text: &str, file: &str, reg: &mut Registry) -> Result<Vec<Loaded>, crate::error::InputError> {
    let mut out = vec![];
    crate::scene::load_plugins(text, file, |p| load(p, reg).map(|l| out.push(l)))?;
    Ok(out)
}

/// The shared library cargo built for crate `crate_name` (its `[lib]` name, with
/// underscores) beside the running program — for a plugin's own tests, examples and
/// benchmarks: in the program's folder, its parent, or their `deps/` (a test runs
/// from target/PROFILE/deps, an example from target/PROFILE/examples). `None` when
/// it is not built.
pub fn built_library(crate_name: &str) -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    let dir = exe.parent()?;
    let name = format!("{}{crate_name}{}", std::env::consts::DLL_PREFIX, std::env::consts::DLL_SUFFIX);
    let mut places = vec![dir.join("deps"), dir.to_path_buf()];
    if let Some(up) = dir.parent() {
        places.extend([up.join("deps"), up.to_path_buf()]);
    }
    places.into_iter().map(|d| d.join(&name)).find(|p| p.exists())
}
