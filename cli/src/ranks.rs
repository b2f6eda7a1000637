//! `nscdd run` as one rank of a multi-process run (`mpirun -n P nscdd run …`, cargo
//! feature `mpi`): starting MPI when a launcher started this process, the agreement
//! of the ranks on the scene before stepping, and the failures of one rank.
//!
//! Failures: a rank that cannot load the scene (or its flags) stops every rank at the
//! agreement that follows loading (exit code 2; rank 0 prints the first failing
//! rank's message, naming the rank, and writes it in OUT/error.txt); ranks that read
//! different scenes stop there too. A rank that fails
//! while the others step (an unwritable output on rank 0, a panic in a plugin)
//! prints its message and aborts every rank (`MPI_Abort`): never a hang. A
//! divergence stops every rank at the same step (the diverging body's state goes to
//! every rank with the step's exchange): rank 0 reports it, every rank exits 1.

use nscdd::dd::Cluster;
use std::hash::{Hash, Hasher};
use std::path::Path;
use std::process::ExitCode;

/// This process's place among the ranks (one process: rank 0 of 1, no MPI).
pub struct Ranks {
    #[cfg(feature = "mpi")]
    session: Option<nscdd::dd::mpi::MpiSession>,
}

/// The rank count an MPI launcher gave this process (1 without a launcher).
#[cfg_attr(feature = "mpi", allow(dead_code))]
/// The number of processes the MPI launcher started (1 without one).
pub fn launched_size() -> u32 {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"]
        .iter()
        .find_map(|v| std::env::var(v).ok()?.parse().ok())
        .unwrap_or(1)
}

impl Ranks {
    /// Starts MPI when this process was started by an MPI launcher.
    pub fn start() -> Result<Ranks, String> {
        #[cfg(feature = "mpi")]
        {
            Ok(Ranks {
                session: nscdd::dd::mpi::MpiSession::from_launcher(),
            })
        }
        #[cfg(not(feature = "mpi"))]
        {
            let n = launched_size();
            if n > 1 {
                return Err(format!(
                    "started as one of {n} MPI ranks, but this nscdd was built without MPI: build it with `cargo build --release --features mpi` (README, \"Running on many cores with MPI\")"
                ));
            }
            Ok(Ranks {})
        }
    }

    pub fn rank(&self) -> u32 {
        #[cfg(feature = "mpi")]
        if let Some(s) = &self.session {
            return s.rank();
        }
        0
    }

    pub fn size(&self) -> u32 {
        #[cfg(feature = "mpi")]
        if let Some(s) = &self.session {
            return s.size();
        }
        1
    }

    pub fn root(&self) -> bool {
        self.rank() == 0
    }

    /// A cluster over the ranks (None without a launcher). Collective: every rank
    /// calls it at the same point.
    pub fn cluster(&self) -> Option<Box<dyn Cluster>> {
        #[cfg(feature = "mpi")]
        if let Some(s) = &self.session {
            return Some(s.cluster());
        }
        None
    }

    /// After loading: every rank says whether it loaded the scene (`Ok(digest)` of
    /// what it will run) or why not. Returns the exit code when the run must stop:
    /// some rank failed (it prints its message; rank 0 also writes it, or a note,
    /// in OUT/error.txt) or the ranks disagree on the scene.
    pub fn agree(&self, loaded: Result<u64, String>, out: &Path) -> Result<(), ExitCode> {
        let Some(mut cl) = self.cluster() else {
            return loaded.map(|_| ()).map_err(|e| crate::report::input_error_in(out, e));
        };
        let (_, failed) = cl.min_max(loaded.is_err() as u64);
        if failed == 1 {
            // rank 0 reports the first failing rank's message (on stderr and in
            // OUT/error.txt): a check of the bodies a rank holds (a scene loaded in
            // part) may fail on some ranks only
            let (first, message) = first_failure(cl.as_mut(), loaded.as_ref().err());
            return Err(match (self.rank(), first) {
                (0, 0) => crate::report::input_error_in(out, message),
                (0, k) => crate::report::input_error_in(out, format!("rank {k}: {message}")),
                _ => ExitCode::from(2),
            });
        }
        let digest = loaded.unwrap_or(0);
        let (lo, hi) = cl.min_max(digest);
        if lo != hi {
            return Err(if self.root() {
                crate::report::input_error_in(
                    out,
                    "the ranks read different scenes, options or restart states: every rank must run the same scene with the same flags and state",
                )
            } else {
                ExitCode::from(2)
            });
        }
        Ok(())
    }

    /// A run that stopped on this rank: with other ranks still stepping, prints the
    /// message with the rank and stops every rank (exit `code`).
    pub fn abort_others(&self, code: i32, msg: &str) -> ExitCode {
        #[cfg(feature = "mpi")]
        if let Some(s) = self.session.as_ref().filter(|s| s.size() > 1) {
            eprintln!("rank {}: error: {msg}", s.rank());
            s.abort(code)
        }
        eprintln!("error: {msg}");
        ExitCode::from(code as u8)
    }
}

/// The lowest rank whose `error` is set, and its message, on every rank (two
/// all-gathers: the lengths, then the messages' bytes). Collective.
fn first_failure(cl: &mut dyn Cluster, error: Option<&String>) -> (u32, String) {
    let p = cl.size() as usize;
    let bytes: Vec<f64> = error.map(|e| e.bytes().map(f64::from).collect()).unwrap_or_default();
    let mut lens = Vec::new();
    cl.all_gather(&[f64::from(u8::from(error.is_some())), bytes.len() as f64], &vec![2; p], &mut lens);
    let counts: Vec<usize> = lens.chunks_exact(2).map(|x| x[1] as usize).collect();
    let mut all = Vec::new();
    cl.all_gather(&bytes, &counts, &mut all);
    let first = lens.chunks_exact(2).position(|x| x[0] > 0.0).unwrap_or(0);
    let start: usize = counts[..first].iter().sum();
    let text: Vec<u8> = all[start..start + counts[first]].iter().map(|&b| b as u8).collect();
    (first as u32, String::from_utf8_lossy(&text).into_owned())
}

/// A panic unwinding through a multi-rank run (a plugin's, or a bug) on one rank:
/// the others may wait for it in a collective, and `MPI_Finalize` (the session's
/// drop, next) would wait for them. The rank prints the message with its rank and
/// stops every rank instead: never a hang.
#[cfg(feature = "mpi")]
impl Drop for Ranks {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            return;
        }
        if let Some(s) = self.session.as_ref().filter(|s| s.size() > 1) {
            let text = crate::plugins::panic_message().unwrap_or_else(|| "internal error".into());
            eprintln!(
                "rank {}: error: {text}; the run stopped, the outputs written so far are kept",
                s.rank()
            );
            s.abort(1)
        }
    }
}

/// What every rank must agree on: the scene file's text, the initial state (its
/// saved form, hashed as `state` writes it: a restart changes it; never held as a
/// text, which for 55 000 spheres and their contacts is ≈ 70 MB), the
/// decomposition and the run's settings.
pub fn digest(scene: &Path, state: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>, settings: impl std::fmt::Debug) -> u64 {
    /// A writer that hashes what it is given.
    struct Hashing<'a>(&'a mut std::collections::hash_map::DefaultHasher);
    impl std::io::Write for Hashing<'_> {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            self.0.write(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let mut h = std::collections::hash_map::DefaultHasher::new();
    std::fs::read(scene).unwrap_or_default().hash(&mut h);
    // (writing into a hasher cannot fail)
    let _ = state(&mut std::io::BufWriter::new(Hashing(&mut h)));
    format!("{settings:?}").hash(&mut h);
    h.finish()
}
