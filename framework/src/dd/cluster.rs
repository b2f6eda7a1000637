//! The processes of a multi-process run, as the NSCDD coordinator sees them.
//!
//! [`Cluster`] is the handful of operations [`super::ranks`] needs: a point-to-point
//! round with a few peers, gathers and a scatter of `f64` buffers, an all-to-all of
//! one count per pair of ranks (who will send to whom), an agreement and an abort.
//! The MPI implementation is [`super::mpi::MpiCluster`] (cargo feature `mpi`);
//! nothing else in the framework names MPI. [`Solo`] is the one-process cluster
//! (every operation a copy), which runs the multi-process code path in one process
//! for tests.
//!
//! Every operation but [`Cluster::exchange`] is collective: every rank calls it, in
//! the same order, with the same `counts`.

/// A group of processes (ranks 0..size) running one simulation together.
pub trait Cluster {
    fn rank(&self) -> u32;
    fn size(&self) -> u32;
    /// One point-to-point round: sends `out[i]` to rank `peers[i]` and receives
    /// `inbox[i]` (resized to the message) from it. The relation is symmetric: each
    /// peer calls `exchange` with this rank among its peers in the same round.
    /// Sends and receives are non-blocking and waited for together.
    fn exchange(&mut self, peers: &[u32], out: &[Vec<f64>], inbox: &mut [Vec<f64>]);
    /// `all` = every rank's `mine` concatenated in rank order (`counts[r]`: rank r's
    /// length, the same on every rank).
    fn all_gather(&mut self, mine: &[f64], counts: &[usize], all: &mut Vec<f64>);
    /// As [`Cluster::all_gather`], into rank 0 only (`all` untouched elsewhere).
    fn gather(&mut self, mine: &[f64], counts: &[usize], all: &mut Vec<f64>);
    /// Rank r receives `all[displ_r .. displ_r + counts[r]]` of rank 0's `all` into
    /// `mine` (displ_r = counts[0] + … + counts[r − 1]).
    fn scatter(&mut self, all: &[f64], counts: &[usize], mine: &mut Vec<f64>);
    /// One value from every rank to every rank (MPI_Alltoall): rank s's `to[r]`
    /// arrives in rank r's `from[s]` (`to`: one value per rank). This default goes
    /// through [`Cluster::all_gather`] (every rank receives every row).
    fn all_to_all(&mut self, to: &[u64], from: &mut Vec<u64>) {
        let (n, me) = (self.size() as usize, self.rank() as usize);
        let mine: Vec<f64> = to.iter().map(|&x| x as f64).collect();
        let mut all = Vec::new();
        self.all_gather(&mine, &vec![n; n], &mut all);
        from.clear();
        from.extend((0..n).map(|s| all[s * n + me] as u64));
    }
    /// The smallest and largest of `x` over the ranks.
    fn min_max(&mut self, x: u64) -> (u64, u64);
    /// Stops every rank at once with exit code `code` (MPI_Abort): for a failure on
    /// one rank, which the others would wait for forever.
    fn abort(&self, code: i32) -> !;
    /// Wall and CPU seconds (the calling thread's) spent in the operations above so
    /// far: a rank's waits, measured apart from its compute.
    fn waited(&self) -> (f64, f64) {
        (0.0, 0.0)
    }
}

/// The peak resident memory of this process so far (MiB; 0 where not available).
pub fn peak_rss_mib() -> f64 {
    #[cfg(unix)]
    {
        // SAFETY: getrusage writes the rusage it is given, nothing else; all-zero
        // bytes are a valid rusage.
        let mut u: libc::rusage = unsafe { std::mem::zeroed() };
        if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } == 0 {
            // kilobytes on Linux, bytes on macOS
            let unit = if cfg!(target_os = "macos") { 1.0 } else { 1024.0 };
            return u.ru_maxrss as f64 * unit / (1024.0 * 1024.0);
        }
    }
    0.0
}

/// CPU seconds of the calling thread (`thread`) or of the whole process (0 where
/// the clock is not available).
pub fn cpu_seconds(thread: bool) -> f64 {
    #[cfg(unix)]
    {
        let clock = if thread {
            libc::CLOCK_THREAD_CPUTIME_ID
        } else {
            libc::CLOCK_PROCESS_CPUTIME_ID
        };
        let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
        // SAFETY: clock_gettime writes the timespec it is given, nothing else.
        if unsafe { libc::clock_gettime(clock, &mut ts) } == 0 {
            return ts.tv_sec as f64 + 1e-9 * ts.tv_nsec as f64;
        }
    }
    let _ = thread;
    0.0
}

/// Adds the wall and thread-CPU seconds since its start to a pair of totals.
pub struct WaitClock {
    wall: std::time::Instant,
    cpu: f64,
}

impl WaitClock {
    pub fn start() -> Self {
        WaitClock {
            wall: std::time::Instant::now(),
            cpu: cpu_seconds(true),
        }
    }
    pub fn stop(self, total: &mut (f64, f64)) {
        total.0 += self.wall.elapsed().as_secs_f64();
        total.1 += cpu_seconds(true) - self.cpu;
    }
}

/// The one-process cluster.
#[derive(Clone, Copy, Debug, Default)]
pub struct Solo;

impl Cluster for Solo {
    fn rank(&self) -> u32 {
        0
    }
    fn size(&self) -> u32 {
        1
    }
    fn exchange(&mut self, peers: &[u32], _out: &[Vec<f64>], _inbox: &mut [Vec<f64>]) {
        assert!(peers.is_empty(), "a one-process cluster has no peers");
    }
    fn all_gather(&mut self, mine: &[f64], _counts: &[usize], all: &mut Vec<f64>) {
        all.clear();
        all.extend_from_slice(mine);
    }
    fn gather(&mut self, mine: &[f64], counts: &[usize], all: &mut Vec<f64>) {
        self.all_gather(mine, counts, all);
    }
    fn scatter(&mut self, all: &[f64], counts: &[usize], mine: &mut Vec<f64>) {
        mine.clear();
        mine.extend_from_slice(&all[..counts[0]]);
    }
    fn min_max(&mut self, x: u64) -> (u64, u64) {
        (x, x)
    }
    fn abort(&self, code: i32) -> ! {
        std::process::exit(code)
    }
}

/// Displacements of `counts` (exclusive prefix sums).
pub fn displacements(counts: &[usize]) -> Vec<usize> {
    let mut d = Vec::with_capacity(counts.len());
    let mut acc = 0;
    for &c in counts {
        d.push(acc);
        acc += c;
    }
    d
}
