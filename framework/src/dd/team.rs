//! Threads sweeping the subdomains, kept for a whole step.
//!
//! The subdomains are split into contiguous groups, one per thread; the calling
//! thread (the coordinator) sweeps group 0. Each stage: the coordinator posts the
//! command, every thread sweeps its group, all meet at a barrier; the gluing stage
//! then runs on the coordinator with every subdomain locked (uncontended). A
//! subdomain is only ever swept by its group's thread, on its own data, so the
//! result does not depend on the number of threads.

use super::subdomain::{Subdomain2, SubdomainSolver};
use std::ops::Range;
use std::sync::{Barrier, Mutex, MutexGuard};

#[derive(Clone, Copy, Default)]
struct Cmd {
    n: u32,
    omega: f64,
    check: bool,
    stop: bool,
}

/// The subdomains of a step, shared between the coordinator and the workers.
pub struct Team<'a, 'b> {
    cells: &'a [Mutex<&'b mut Subdomain2>],
    groups: Vec<Range<usize>>,
    start: Barrier,
    done: Barrier,
    cmd: Mutex<Cmd>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl<'a, 'b> Team<'a, 'b> {
    fn sweep_group(&self, g: usize, c: Cmd) {
        for k in self.groups[g].clone() {
            lock(&self.cells[k]).sweeps(c.n, c.omega, c.check);
        }
    }

    /// `n` sweeps in every subdomain (the last a check pass when `check`).
    pub fn sweep(&self, n: u32, omega: f64, check: bool) {
        let c = Cmd {
            n,
            omega,
            check,
            stop: false,
        };
        if self.groups.len() == 1 {
            return self.sweep_group(0, c);
        }
        *lock(&self.cmd) = c;
        self.start.wait();
        self.sweep_group(0, c);
        self.done.wait();
    }

    /// Runs `f` on all the subdomains, in subdomain order, on the coordinator.
    pub fn with_all<R>(&self, f: impl FnOnce(&mut [&mut Subdomain2]) -> R) -> R {
        let mut guards: Vec<_> = self.cells.iter().map(lock).collect();
        let mut subs: Vec<&mut Subdomain2> = guards.iter_mut().map(|g| &mut ***g).collect();
        f(&mut subs)
    }

    fn work(&self, g: usize) {
        loop {
            self.start.wait();
            let c = *lock(&self.cmd);
            if c.stop {
                return;
            }
            self.sweep_group(g, c);
            self.done.wait();
        }
    }

    fn stop(&self) {
        if self.groups.len() > 1 {
            lock(&self.cmd).stop = true;
            self.start.wait();
        }
    }
}

/// Releases the workers when the coordinator leaves (also on a panic).
struct StopOnDrop<'t, 'a, 'b>(&'t Team<'a, 'b>);
impl Drop for StopOnDrop<'_, '_, '_> {
    fn drop(&mut self) {
        self.0.stop();
    }
}

/// Runs `driver` with a [`Team`] of `threads` threads over `subs`.
pub fn with_team<R>(subs: &mut [Subdomain2], threads: usize, driver: impl FnOnce(&Team<'_, '_>) -> R) -> R {
    let n = subs.len();
    let groups_n = threads.clamp(1, n.max(1));
    let chunk = n.div_ceil(groups_n).max(1);
    let groups: Vec<Range<usize>> = (0..n.div_ceil(chunk).max(1)).map(|g| g * chunk..((g + 1) * chunk).min(n)).collect();
    let cells: Vec<Mutex<&mut Subdomain2>> = subs.iter_mut().map(Mutex::new).collect();
    let team = Team {
        cells: &cells,
        start: Barrier::new(groups.len()),
        done: Barrier::new(groups.len()),
        cmd: Mutex::new(Cmd::default()),
        groups,
    };
    if team.groups.len() == 1 {
        return driver(&team);
    }
    std::thread::scope(|sc| {
        for g in 1..team.groups.len() {
            let t = &team;
            sc.spawn(move || t.work(g));
        }
        let _stop = StopOnDrop(&team);
        driver(&team)
    })
}
