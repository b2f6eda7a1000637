//! Resource limits checked before a scene is built: a generator asked for more
//! bodies (or working memory) than the machine can hold is refused, naming its key
//! and the estimate, instead of allocating until the process aborts or hangs.
//!
//! The limit is [`crate::registry::Registry::set_max_memory`] (the CLI's
//! `--max-memory`), else the machine's available memory (`MemAvailable` of
//! `/proc/meminfo`), else 16 GiB. The estimate of a body covers its state, its
//! shape, its share of the contact set (a few contacts per body) and detection;
//! it is an order of magnitude, meant to refuse the absurd (a count of 10¹²)
//! rather than to budget a run to the byte.
//!
//! ```
//! use nscdd::registry::limits::{bytes_per_body, human, parse_size};
//! assert_eq!(parse_size("8G").unwrap(), 8.0 * 1024f64.powi(3));
//! // what 10¹² spheres would need: refused by `SceneBuilder::reserve`
//! let need = 1e12 * bytes_per_body::<nscdd::dim::D3>();
//! assert!(human(need).ends_with("PB"), "{}", human(need));
//! ```
//! ```

use crate::dim::Dim;
use crate::model::ShapeRef;
use std::mem::size_of;

/// Bytes a body of dimension D holds, all stages included (an estimate).
pub fn bytes_per_body<D: Dim>() -> f64 {
    let state = size_of::<D::Point>()
        + size_of::<D::Rot>()
        + 3 * size_of::<D::Twist>() // V, V⁻, reaction
        + size_of::<D::InvMass>()
        + size_of::<D::Inertia>()
        + size_of::<ShapeRef>()
        + 8 // mass
        + 4 // material, free
        + size_of::<Option<String>>()
        + 16; // fixed, origin
              // contacts: ~2 per body in 2D, ~3 in 3D (half the coordination), each with its
              // frame, block, impulse, free velocity, key, joint, point and the next step's copy
    let per_contact = 2 * (8 + size_of::<D::Frame>() + size_of::<D::Block>() + 2 * size_of::<D::Local>() + 64 + size_of::<D::Point>());
    let contacts = if D::N == 2 { 2.0 } else { 3.0 } * per_contact as f64;
    // shape store entry, broad-phase cell entry and bounding box
    let shape = 64.0 + 2.0 * size_of::<D::Point>() as f64;
    state as f64 + contacts + shape
}

/// The memory a scene may use (bytes): `limit` when set, else the machine's
/// available memory, else 16 GiB.
pub fn memory_limit(limit: Option<f64>) -> (f64, &'static str) {
    if let Some(l) = limit {
        return (l, "--max-memory");
    }
    match available_memory() {
        Some(m) => (m, "the memory available on this machine"),
        None => (16.0 * GIB, "a default of 16 GiB"),
    }
}

/// Ok when `need` bytes fit in the memory limit (`max_memory`, else the machine's:
/// [`memory_limit`]); Err: [`refusal`].
pub fn check(need: f64, max_memory: Option<f64>, what: &str) -> Result<(), String> {
    let (limit, _) = memory_limit(max_memory);
    if need.is_finite() && need <= limit {
        return Ok(());
    }
    Err(refusal(need, max_memory, what))
}

/// "needs ≈ … (`what` the bytes are for), more than … (the limit's source)", for the
/// caller to complete with what to do.
pub fn refusal(need: f64, max_memory: Option<f64>, what: &str) -> String {
    let (limit, source) = memory_limit(max_memory);
    format!("needs ≈ {} ({what}), more than {} ({source})", human(need), human(limit))
}

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

fn available_memory() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// A size for messages: `2.5 GB`, `80 TB`.
pub fn human(bytes: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut x = bytes;
    let mut u = 0;
    while x >= 1000.0 && u + 1 < units.len() {
        x /= 1000.0;
        u += 1;
    }
    if !x.is_finite() {
        return "an unbounded amount".into();
    }
    if x >= 1000.0 {
        return format!("{bytes:.1e} B");
    }
    format!("{} {}", if x < 10.0 { format!("{x:.1}") } else { format!("{x:.0}") }, units[u])
}

/// Parses `--max-memory`: bytes, or a number with a unit (`500M`, `8G`, `2T`; k, M,
/// G, T powers of 1024).
pub fn parse_size(s: &str) -> Result<f64, String> {
    let t = s.trim();
    let (num, mult) = match t.chars().last() {
        Some(c @ ('k' | 'K' | 'm' | 'M' | 'g' | 'G' | 't' | 'T')) => {
            let p = match c.to_ascii_uppercase() {
                'K' => 1,
                'M' => 2,
                'G' => 3,
                _ => 4,
            };
            (&t[..t.len() - 1], 1024f64.powi(p))
        }
        _ => (t, 1.0),
    };
    match num.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x * mult),
        _ => Err(format!("--max-memory: expected a size such as 8G, 500M or 1e9, got `{s}`")),
    }
}
