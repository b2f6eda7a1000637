//! A library whose entry point announces another plugin interface version: nscdd
//! must refuse it with exit 2, reading nothing but the version.

use nscdd::plugin::PluginEntry;
use std::ffi::{c_char, c_void};

unsafe extern "C" fn register(_reg: *mut c_void) -> *const c_char {
    // never called: the version differs
    std::process::abort()
}

/// The entry point, as an older or newer nscdd would have made it.
#[no_mangle]
pub extern "C" fn nscdd_plugin_entry() -> *const PluginEntry {
    let e = nscdd::plugin::entry("nscdd_plugin_bad_abi\0", register);
    // an entry of interface version ABI_VERSION + 1 (a copy: the framework's is static)
    static mut OTHER: Option<PluginEntry> = None;
    // SAFETY: written once, before the host reads it (one loader thread)
    unsafe {
        let mut copy = std::ptr::read(e);
        copy.abi = nscdd::plugin::ABI_VERSION + 1;
        OTHER = Some(copy);
        (*std::ptr::addr_of!(OTHER)).as_ref().unwrap() as *const PluginEntry
    }
}
