//! Plugins loaded at run time (`--plugin PATH`, a scene's `[[plugins]]`), the
//! `nscdd plugins` listing, and panics reported with the plugin they came from
//! (docs/PLUGINS.md).

use nscdd::registry::Registry;
use std::path::Path;
use std::process::ExitCode;
use std::sync::Mutex;

/// The command line's `--plugin` libraries, loaded into `reg`.
pub fn load_cli(paths: &[std::path::PathBuf], reg: &mut Registry) -> Result<(), String> {
    for p in paths {
        nscdd::plugin::load(p, reg).map_err(|m| format!("--plugin: {m}"))?;
    }
    Ok(())
}

/// The plugins a scene file names (`[[plugins]]`), loaded into `reg` before the scene
/// is read. A file that cannot be read is left to the scene's loader.
pub fn load_for_scene(scene: &Path, reg: &mut Registry) -> Result<(), nscdd::error::InputError> {
    let Ok(text) = std::fs::read_to_string(scene) else { return Ok(()) };
    nscdd::plugin::load_for_scene(&text, &scene.display().to_string(), reg).map(|_| ())
}

/// `nscdd plugins`: every plugin, built in or loaded, with what it registers.
pub fn list(reg: &Registry) -> ExitCode {
    let loaded = nscdd::plugin::loaded();
    println!(
        "plugin interface version {}, nscdd {}, {}",
        nscdd::plugin::ABI_VERSION,
        nscdd::plugin::NSCDD_VERSION,
        nscdd::plugin::RUSTC_VERSION
    );
    // the framework's own laws and writers: registered before any plugin
    let by_plugins: Vec<String> = reg.plugin_contents().into_iter().flat_map(|(_, i)| i).collect();
    println!("framework (built in)");
    for i in reg.contents().into_iter().filter(|i| !by_plugins.contains(i)) {
        println!("  {i}");
    }
    for (name, items) in reg.plugin_contents() {
        let from = loaded
            .iter()
            .find(|l| l.plugins.iter().any(|p| p == name))
            .map(|l| format!(" (loaded from {})", l.library.display()))
            .unwrap_or_else(|| " (built in)".into());
        println!("{name}{from}");
        for i in items {
            println!("  {i}");
        }
    }
    ExitCode::SUCCESS
}

/// The first panic of the process: its message and where it happened.
static PANIC: Mutex<Option<String>> = Mutex::new(None);

/// Records panics instead of printing them: [`report`] says what happened. A
/// run-time plugin's panic comes as a `PluginPanic` naming the plugin (raised by
/// its guard, `nscdd::registry::guard`).
pub fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        let text = match info.payload().downcast_ref::<nscdd::registry::guard::PluginPanic>() {
            Some(p) => p.0.clone(),
            None => {
                let msg = nscdd::plugin::panic_text(info.payload());
                let at = info
                    .location()
                    .map(|l| format!(" at {}:{}", l.file(), l.line()))
                    .unwrap_or_default();
                format!("internal error (a bug, please report it): {msg}{at}")
            }
        };
        if let Ok(mut first) = PANIC.lock() {
            first.get_or_insert(text);
        }
    }));
}

/// A caught panic: its message, and exit 1 (the outputs written so far are kept).
pub fn report(payload: Box<dyn std::any::Any + Send>) -> ExitCode {
    let text = panic_message().unwrap_or_else(|| format!("internal error: {}", nscdd::plugin::panic_text(&*payload)));
    eprintln!("error: {text}; the run stopped, the outputs written so far are kept");
    ExitCode::from(1)
}

/// The message of the first panic the hook saw (`None` before any).
pub fn panic_message() -> Option<String> {
    PANIC.lock().ok().and_then(|p| p.clone())
}
