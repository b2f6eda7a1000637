//! Threads sweeping and gluing the subdomains.
//!
//! The subdomains are split into groups, one per thread, balanced by contact count
//! (the sweep's cost); the calling thread (the coordinator) runs group 0, the
//! others run on [`Workers`], a rayon thread pool kept across steps (each worker
//! blocks in its group's loop for the step), and [`ThreadChoice`] drops to one
//! thread while the threads do not pay (a busy machine). The
//! coordinator posts a *phase* (a command), every thread runs it on its group, and
//! the coordinator waits until all are done; a phase costs two one-way signals, each
//! waited for by spinning ([`Parker`]: `spin_loop` for a bounded time, then a
//! condition variable), so that a wake-up costs well under a microsecond where a
//! parked thread's costs tens (std's `Barrier` parks at once: with it, two threads
//! were slower than one).
//!
//! With the decentralized scheme the gluing runs in the groups too: after its sweeps
//! a subdomain *posts* its packets (its copies' velocities of the bodies shared with
//! each neighbor, [`schemes::post`]) into its outbox; once every subdomain has
//! posted, each one reads its neighbors' packets addressed to it and glues its own
//! copies ([`schemes::glue_sub`]). That gluing is put off to the start of the next
//! stage's phase, so that a stage is one phase: `glue(n − 1), sweep(n), post(n)`.
//! Outboxes alternate between two buffers by stage parity: a phase reads the parity
//! posted by the previous one and writes the other. A check stage adds a gluing
//! phase, whose residual shares the convergence test needs. The centralized scheme
//! glues on the coordinator with every subdomain locked (uncontended).
//!
//! A subdomain is only ever swept and glued by its group's thread, on its own data
//! and the packets, which are copies; each subdomain's arithmetic is the serial one
//! ([`schemes::glue_stage`]) and every reduction runs in subdomain order, so the
//! result does not depend on the number of threads.

use super::family::Family;
use super::gluing::GluePartial;
use super::partition::Interface;
use super::schemes::{self, glue_stage, ChainBuffers, GlueBuffers, Scheme};
use super::subdomain::{Subdomain, SubdomainSolver};
use super::transport::Transport;
use crate::norms::Sums;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, AtomicUsize, Ordering::Relaxed, Ordering::SeqCst};
use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// The longest a thread spins before it parks: longer than the coordinator's serial
/// work between two phases and a phase's imbalance, far shorter than a step.
const SPIN_MAX: u64 = 200_000;
/// The shortest spin (ns): a phase's usual end-of-phase imbalance on a quiet machine.
const SPIN_MIN: u64 = 5_000;

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Waiting for a condition set by another thread: spin, then park. No
/// `yield_now`: on a loaded machine it hands the core to another process for a
/// whole time slice.
///
/// The spin bound adapts: halved (down to [`SPIN_MIN`]) after a wait that had to
/// park, doubled (up to [`SPIN_MAX`]) after one that ended while spinning. On a
/// quiet machine a phase's waits end within microseconds and the bound stays at
/// its maximum (a park once a step, at the serial work between steps, costs one
/// halving). When the team has fewer cores than threads (another process busy),
/// the thread that spins holds the core its partner needs, no wait ends while
/// spinning, and the bound falls to the minimum within a few phases instead of
/// costing [`SPIN_MAX`] a phase. The bound only changes timing, never results.
struct Parker {
    sleepers: AtomicU32,
    m: Mutex<()>,
    cv: Condvar,
    /// The current spin bound (ns).
    spin: AtomicU64,
}

impl Default for Parker {
    fn default() -> Self {
        Parker {
            sleepers: AtomicU32::new(0),
            m: Mutex::new(()),
            cv: Condvar::new(),
            spin: AtomicU64::new(SPIN_MAX),
        }
    }
}

impl Parker {
    /// Returns once `ready()` (which must load with `SeqCst`) holds.
    fn wait(&self, ready: impl Fn() -> bool) {
        let t0 = Instant::now();
        let bound = Duration::from_nanos(self.spin.load(Relaxed));
        let mut i = 0u32;
        while !ready() {
            std::hint::spin_loop();
            i = i.wrapping_add(1);
            if i.is_multiple_of(64) && t0.elapsed() > bound {
                let halved = (bound.as_nanos() as u64 / 2).max(SPIN_MIN);
                self.spin.store(halved, Relaxed);
                let mut g = lock(&self.m);
                // sleepers before ready(), against wake()'s store then load: one of
                // the two sees the other (SeqCst)
                self.sleepers.fetch_add(1, SeqCst);
                while !ready() {
                    g = self.cv.wait(g).unwrap_or_else(|e| e.into_inner());
                }
                self.sleepers.fetch_sub(1, SeqCst);
                return;
            }
        }
        if i > 0 {
            let doubled = (2 * bound.as_nanos() as u64).min(SPIN_MAX);
            self.spin.store(doubled, Relaxed);
        }
    }

    /// To call after the store that makes a waiter's condition true (`SeqCst`).
    fn wake(&self) {
        if self.sleepers.load(SeqCst) > 0 {
            drop(lock(&self.m));
            self.cv.notify_all();
        }
    }
}

#[derive(Clone, Copy, Default)]
struct Cmd {
    /// Glue from the packets of this parity first.
    glue_from: Option<usize>,
    /// Then `n` sweeps (the last a check pass when `check`) and post to `post_to`.
    sweep: bool,
    n: u32,
    omega: f64,
    check: bool,
    post_to: Option<usize>,
    stop: bool,
}

/// A subdomain's packets of one stage parity, one per neighbor (neighbor order).
type Outbox = Mutex<Vec<Vec<f64>>>;

/// What the threads share.
struct Shared<'a, 'b, D: Family> {
    cells: &'a [Mutex<&'b mut Subdomain<D>>],
    /// Per subdomain and parity: one packet per neighbor, neighbor order.
    outbox: &'a [[Outbox; 2]],
    /// Per subdomain, per neighbor: (neighbor, index of the subdomain among its neighbors).
    back: &'a [Vec<(usize, usize)>],
    /// Per subdomain: residual share of its last gluing.
    partials: &'a [Mutex<GluePartial>],
    iface: &'a Interface,
    groups: Vec<Vec<usize>>,
    cmd: Mutex<Cmd>,
    /// Phases posted / finished by the workers (cumulative).
    epoch: AtomicUsize,
    done: AtomicUsize,
    failed: AtomicBool,
    go: Parker,
    finished: Parker,
}

/// Per-thread buffers.
#[derive(Default)]
struct Scratch {
    packets: Vec<Vec<f64>>,
    chain: ChainBuffers,
}

impl<D: Family> Shared<'_, '_, D> {
    fn run_group(&self, g: usize, c: Cmd, buf: &mut Scratch) {
        for &k in &self.groups[g] {
            let mut s = lock(&self.cells[k]);
            if let Some(q) = c.glue_from {
                let back = &self.back[k];
                buf.packets.resize_with(buf.packets.len().max(back.len()), Vec::new);
                for (p, &(t, j)) in buf.packets.iter_mut().zip(back) {
                    p.clear();
                    p.extend_from_slice(&lock(&self.outbox[t][q])[j]);
                }
                *lock(&self.partials[k]) = schemes::glue_sub(&mut s, &buf.packets, self.iface, false, &mut buf.chain);
            }
            if c.sweep {
                s.sweeps(c.n, c.omega, c.check);
            }
            if let Some(p) = c.post_to {
                schemes::post(&s, &mut lock(&self.outbox[k][p]));
            }
        }
    }

    fn work(&self, g: usize) {
        struct Fail<'s, 'a, 'b, D: Family>(&'s Shared<'a, 'b, D>);
        impl<D: Family> Drop for Fail<'_, '_, '_, D> {
            fn drop(&mut self) {
                if std::thread::panicking() {
                    self.0.failed.store(true, SeqCst);
                    self.0.finished.wake();
                }
            }
        }
        let _fail = Fail(self);
        let mut buf = Scratch::default();
        let mut seen = 0;
        loop {
            self.go.wait(|| self.epoch.load(SeqCst) > seen);
            seen += 1;
            let c = *lock(&self.cmd);
            if c.stop {
                return;
            }
            self.run_group(g, c, &mut buf);
            self.done.fetch_add(1, SeqCst);
            self.finished.wake();
        }
    }
}

/// The coordinator's handle on the subdomains of a step.
pub struct Team<'s, 'a, 'b, D: Family> {
    sh: &'s Shared<'a, 'b, D>,
    buf: Scratch,
    phases: usize,
    /// Stage parity of the next post.
    parity: usize,
    /// Packets posted and not glued yet (their parity).
    pending: Option<usize>,
    /// (from, to, values) of the decentralized exchange, counted once per gluing.
    links: Vec<(u32, u32, usize)>,
}

impl<D: Family> Team<'_, '_, '_, D> {
    /// Runs `c` on every group, group 0 here; returns when all are done.
    fn phase(&mut self, c: Cmd) {
        let sh = self.sh;
        if sh.groups.len() == 1 {
            return sh.run_group(0, c, &mut self.buf);
        }
        *lock(&sh.cmd) = c;
        self.phases += 1;
        sh.epoch.store(self.phases, SeqCst);
        sh.go.wake();
        sh.run_group(0, c, &mut self.buf);
        let target = self.phases * (sh.groups.len() - 1);
        sh.finished.wait(|| sh.done.load(SeqCst) >= target || sh.failed.load(SeqCst));
        assert!(!sh.failed.load(SeqCst), "a subdomain thread panicked");
    }

    /// Applies the pending gluing, if any.
    fn flush(&mut self) {
        if let Some(q) = self.pending.take() {
            self.phase(Cmd {
                glue_from: Some(q),
                ..Cmd::default()
            });
        }
    }

    /// `n` sweeps in every subdomain (the last a check pass when `check`).
    pub fn sweep(&mut self, n: u32, omega: f64, check: bool) {
        self.flush();
        self.phase(Cmd {
            sweep: true,
            n,
            omega,
            check,
            ..Cmd::default()
        });
    }

    /// One stage: `n` sweeps in every subdomain (the last a check pass when `check`),
    /// then one gluing stage (as [`glue_stage`] on all the subdomains). With `check`,
    /// returns the check pass's sums merged in subdomain order and each subdomain's
    /// residual share (else default sums and no shares). The decentralized gluing
    /// runs in parallel, and outside check stages at the start of the next phase
    /// (any call but `stage` applies it first).
    pub fn stage(
        &mut self,
        n: u32,
        omega: f64,
        check: bool,
        scheme: Scheme,
        t: &mut dyn Transport,
        bufs: &mut GlueBuffers,
    ) -> (Sums, Vec<GluePartial>) {
        let iface = self.sh.iface;
        let parts = if scheme == Scheme::Decentralized && !iface.is_empty() {
            let p = self.parity;
            self.parity ^= 1;
            let glue_from = self.pending.take();
            self.phase(Cmd {
                glue_from,
                sweep: true,
                n,
                omega,
                check,
                post_to: Some(p),
                stop: false,
            });
            for &(from, to, len) in &self.links {
                t.record(from, to, len);
            }
            self.pending = Some(p);
            if check {
                self.flush();
                self.sh.partials.iter().map(|m| *lock(m)).collect()
            } else {
                Vec::new()
            }
        } else {
            self.sweep(n, omega, check);
            if iface.is_empty() {
                Vec::new()
            } else {
                self.with_all(|subs| glue_stage(subs, iface, scheme, t, false, bufs))
            }
        };
        let mut sums = Sums::default();
        if check {
            // reduced in subdomain order
            for c in self.sh.cells {
                sums.merge(lock(c).sums());
            }
        }
        (sums, parts)
    }

    /// Runs `f` on all the subdomains, in subdomain order, on the coordinator.
    pub fn with_all<R>(&mut self, f: impl FnOnce(&mut [&mut Subdomain<D>]) -> R) -> R {
        self.flush();
        let mut guards: Vec<_> = self.sh.cells.iter().map(lock).collect();
        let mut subs: Vec<&mut Subdomain<D>> = guards.iter_mut().map(|g| &mut ***g).collect();
        f(&mut subs)
    }
}

/// Releases the workers when the coordinator leaves (also on a panic).
struct StopOnDrop<'s, 'a, 'b, D: Family>(&'s Shared<'a, 'b, D>);
impl<D: Family> Drop for StopOnDrop<'_, '_, '_, D> {
    fn drop(&mut self) {
        let sh = self.0;
        if sh.groups.len() > 1 {
            lock(&sh.cmd).stop = true;
            sh.epoch.fetch_add(1, SeqCst);
            sh.go.wake();
        }
    }
}

/// Groups of subdomains, one per thread, balanced by contact count (largest first to
/// the least loaded group; ties to the smaller id); each group in subdomain order.
fn groups<D: Family>(subs: &[Subdomain<D>], threads: usize, mine: &dyn Fn(usize) -> bool) -> Vec<Vec<usize>> {
    let mut by_load: Vec<usize> = (0..subs.len()).filter(|&k| mine(k)).collect();
    let n = threads.clamp(1, by_load.len().max(1));
    by_load.sort_by_key(|&k| (std::cmp::Reverse(subs[k].n_contacts()), k));
    let mut g = vec![Vec::new(); n];
    let mut load = vec![0usize; n];
    for k in by_load {
        let i = (0..n).min_by_key(|&i| (load[i], i)).unwrap_or(0);
        load[i] += subs[k].n_contacts();
        g[i].push(k);
    }
    for x in g.iter_mut() {
        x.sort_unstable();
    }
    g.retain(|x| !x.is_empty());
    if g.is_empty() {
        g.push(Vec::new());
    }
    g
}

/// The worker threads of a run's teams, kept across steps: a team of T threads
/// runs its groups 1..T on T − 1 of them (the calling thread runs group 0).
#[derive(Default)]
pub struct Workers {
    pool: Option<rayon::ThreadPool>,
}

impl Workers {
    /// A pool of at least `n` threads (built once, grown when more are asked for);
    /// None when the system refuses threads (the team then spawns its own).
    pub(crate) fn pool(&mut self, n: usize) -> Option<&rayon::ThreadPool> {
        if self.pool.as_ref().is_none_or(|p| p.current_num_threads() < n) {
            let built = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .thread_name(|i| format!("nscdd-subdomains-{}", i + 1))
                .build();
            self.pool = built.ok();
        }
        self.pool.as_ref()
    }
}

/// Runs `driver` with a [`Team`] of `threads` threads over the subdomains `k` of
/// `subs` for which `mine(k)` (on MPI ranks: the rank's own; all in one process),
/// glued across `iface`; a gluing left pending is applied before returning. The
/// team's other threads come from `workers`.
pub fn with_team<D: Family, R>(
    subs: &mut [Subdomain<D>],
    (threads, mine): (usize, &dyn Fn(usize) -> bool),
    iface: &Interface,
    workers: &mut Workers,
    driver: impl FnOnce(&mut Team<'_, '_, '_, D>) -> R,
) -> R {
    let groups = groups(subs, threads, mine);
    let mut links = Vec::new();
    let back: Vec<Vec<(usize, usize)>> = subs
        .iter()
        .map(|s| {
            s.neighbors
                .iter()
                .map(|nbr| {
                    links.push((s.id, nbr.sub, nbr.values as usize));
                    let t = nbr.sub as usize;
                    let j = subs[t].neighbors.iter().position(|m| m.sub == s.id);
                    (t, j.expect("neighbors are mutual"))
                })
                .collect()
        })
        .collect();
    let outbox: Vec<[Outbox; 2]> = subs.iter().map(|_| [Mutex::new(Vec::new()), Mutex::new(Vec::new())]).collect();
    let partials: Vec<Mutex<GluePartial>> = subs.iter().map(|_| Default::default()).collect();
    let cells: Vec<Mutex<&mut Subdomain<D>>> = subs.iter_mut().map(Mutex::new).collect();
    let sh = Shared {
        cells: &cells,
        outbox: &outbox,
        back: &back,
        partials: &partials,
        iface,
        groups,
        cmd: Mutex::new(Cmd::default()),
        epoch: AtomicUsize::new(0),
        done: AtomicUsize::new(0),
        failed: AtomicBool::new(false),
        go: Parker::default(),
        finished: Parker::default(),
    };
    let mut team = Team {
        sh: &sh,
        buf: Scratch::default(),
        phases: 0,
        parity: 0,
        pending: None,
        links,
    };
    let drive = move || {
        let r = driver(&mut team);
        team.flush();
        r
    };
    if sh.groups.len() == 1 {
        return drive();
    }
    // each worker blocks in its group's loop until the team stops: the pool must
    // hold one idle thread per group (it serves nothing else)
    match workers.pool(sh.groups.len() - 1) {
        Some(pool) => pool.in_place_scope(|sc| {
            for g in 1..sh.groups.len() {
                let s = &sh;
                sc.spawn(move |_| s.work(g));
            }
            let _stop = StopOnDrop(&sh);
            drive()
        }),
        None => std::thread::scope(|sc| {
            for g in 1..sh.groups.len() {
                let s = &sh;
                sc.spawn(move || s.work(g));
            }
            let _stop = StopOnDrop(&sh);
            drive()
        }),
    }
}

/// Steps between two probes of [`ThreadChoice`] while the threads pay; doubled
/// after each probe they lose, up to [`PROBE_MAX`].
pub const PROBE_EVERY: u64 = 50;
pub const PROBE_MAX: u64 = 800;
/// How much slower per stage than one thread the threads must be to be dropped:
/// a margin for the step-to-step scatter of a probe (with one core for two
/// threads they are 2–3× slower).
pub const SLOWER: f64 = 1.25;

/// Whether a step's team runs the requested threads or one: threads that do not
/// pay (fewer free cores than threads, as when another process keeps a core busy,
/// and the threads then take turns on one core at every phase) are dropped until
/// the next probe. A probe is three steps: one on one thread, then two on the
/// requested threads (the faster of the two counts: the first threaded step of a
/// run also starts the workers), each timed per stage. Until the next probe the
/// steps run one thread if the threads were more than [`SLOWER`] times slower,
/// else the threads. Probes come every [`PROBE_EVERY`] steps while the threads pay,
/// and twice as far apart after each probe they lose (up to [`PROBE_MAX`]), so that
/// a busy machine pays for few threaded probes. The team's results do not depend
/// on its thread count: the choice changes timing only, never results.
#[derive(Clone, Debug)]
pub struct ThreadChoice {
    /// Seconds per stage on one thread and on the requested threads (last probe).
    one: f64,
    many: f64,
    /// The first step of the next probe, and the steps between probes.
    next: u64,
    every: u64,
    serial: bool,
}

impl Default for ThreadChoice {
    fn default() -> Self {
        ThreadChoice {
            one: 0.0,
            many: f64::INFINITY,
            next: 1,
            every: PROBE_EVERY,
            serial: false,
        }
    }
}

impl ThreadChoice {
    /// The threads of step `step` (counted from 1) when `requested` are asked for.
    pub fn threads(&self, step: u64, requested: usize) -> usize {
        let probe = step.wrapping_sub(self.next);
        match probe {
            _ if requested <= 1 => 1,
            0 => 1,
            1 | 2 => requested,
            _ if self.serial => 1,
            _ => requested,
        }
    }

    /// Records the solve of step `step`: its seconds and stages.
    pub fn record(&mut self, step: u64, seconds: f64, stages: u32) {
        let per = seconds / f64::from(stages.max(1));
        match step.wrapping_sub(self.next) {
            0 => self.one = per,
            1 => self.many = per,
            2 => {
                self.many = self.many.min(per);
                self.serial = self.many > SLOWER * self.one;
                self.every = if self.serial {
                    (2 * self.every).min(PROBE_MAX)
                } else {
                    PROBE_EVERY
                };
                self.next = step - 2 + self.every;
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{ThreadChoice, PROBE_EVERY};

    /// Probes one thread then the threads every PROBE_EVERY steps; in between, the
    /// threads unless they were more than SLOWER times slower per stage.
    #[test]
    fn thread_choice_probes_and_keeps_the_faster() {
        let mut c = ThreadChoice::default();
        assert_eq!(c.threads(5, 1), 1);
        let probe = |c: &mut ThreadChoice, at: u64, one: f64, many: [f64; 2]| {
            assert_eq!([0, 1, 2].map(|k| c.threads(at + k, 2)), [1, 2, 2]);
            c.record(at, one, 100);
            c.record(at + 1, many[0], 100);
            c.record(at + 2, many[1], 100);
        };
        // 10 ms a stage on one thread; 30 ms (starting the workers), then 12 ms on two
        probe(&mut c, 1, 1.0, [3.0, 1.2]);
        assert_eq!(c.threads(4, 2), 2);
        assert_eq!(c.threads(PROBE_EVERY, 2), 2);
        // two threads on one core: one thread until a probe twice as far
        probe(&mut c, 1 + PROBE_EVERY, 1.0, [3.0, 2.8]);
        assert_eq!(c.threads(PROBE_EVERY + 4, 2), 1);
        assert_eq!(c.threads(2 * PROBE_EVERY + 1, 2), 1);
        probe(&mut c, 1 + 3 * PROBE_EVERY, 1.0, [3.0, 2.8]);
        assert_eq!(c.threads(3 * PROBE_EVERY + 4, 2), 1);
        // the machine is free again at the probe four intervals later
        probe(&mut c, 1 + 7 * PROBE_EVERY, 1.0, [0.6, 0.7]);
        assert_eq!(c.threads(7 * PROBE_EVERY + 4, 2), 2);
        c.record(7 * PROBE_EVERY + 5, 9.0, 100); // not a probe: ignored
        assert_eq!(c.threads(7 * PROBE_EVERY + 6, 2), 2);
    }
}
