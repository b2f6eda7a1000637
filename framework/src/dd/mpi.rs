//! The MPI transport (cargo feature `mpi`, rsmpi): [`Cluster`] over an MPI
//! communicator. The only module of the framework that names MPI.
//!
//! ```no_run
//! # use nscdd::dd::{mpi::MpiSession, DdSettings, Nscdd};
//! // in a program started by `mpirun -n 2 …`
//! let session = MpiSession::from_launcher().expect("started by mpirun");
//! let settings = DdSettings { nx: 2, ny: 1, ..DdSettings::default() };
//! let solver = Nscdd::new(settings).with_cluster(session.cluster()).unwrap();
//! ```
//!
//! Each cluster works on its own duplicate of `MPI_COMM_WORLD`, so that its
//! messages never match another's. Point-to-point rounds post every send
//! non-blocking (`MPI_Isend`), then receive each peer's message after a matched
//! probe (`MPI_Mprobe`, `MPI_Mrecv`: its length is read from the probe), then wait
//! for the sends.

use super::cluster::{displacements, Cluster, WaitClock};
use mpi::datatype::{Partition, PartitionMut};
use mpi::topology::{Communicator, SimpleCommunicator};
use mpi::traits::*;
use mpi::Count;

/// Tag of the interface messages.
const TAG: i32 = 17;

/// MPI, initialized for this process; finalized when dropped (after every
/// [`MpiCluster`] made from it).
pub struct MpiSession {
    universe: mpi::environment::Universe,
}

impl MpiSession {
    /// Whether this process was started by an MPI launcher (OpenMPI's `mpirun`,
    /// MPICH's or Intel's `mpiexec`, Slurm's `srun` with PMI/PMIx).
    pub fn launched() -> bool {
        ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMI_RANK", "PMIX_RANK"]
            .iter()
            .any(|v| std::env::var_os(v).is_some())
    }

    /// Initializes MPI when [`MpiSession::launched`] (None otherwise, or when MPI was
    /// already initialized).
    pub fn from_launcher() -> Option<MpiSession> {
        if !Self::launched() {
            return None;
        }
        mpi::initialize().map(|universe| MpiSession { universe })
    }

    pub fn rank(&self) -> u32 {
        self.universe.world().rank() as u32
    }
    pub fn size(&self) -> u32 {
        self.universe.world().size() as u32
    }

    /// Stops every rank now (`MPI_Abort` on the world communicator: needs no other
    /// rank's cooperation).
    pub fn abort(&self, code: i32) -> ! {
        self.universe.world().abort(code)
    }

    /// A cluster over all the ranks, on its own communicator (collective: every rank
    /// calls it).
    pub fn cluster(&self) -> Box<dyn Cluster> {
        Box::new(MpiCluster {
            comm: self.universe.world().duplicate(),
            wait: (0.0, 0.0),
        })
    }
}

/// [`Cluster`] over an MPI communicator.
pub struct MpiCluster {
    comm: SimpleCommunicator,
    /// Wall and CPU seconds in communication ([`Cluster::waited`]).
    wait: (f64, f64),
}

fn counts_displs(counts: &[usize]) -> (Vec<Count>, Vec<Count>) {
    let c = counts.iter().map(|&x| x as Count).collect();
    let d = displacements(counts).into_iter().map(|x| x as Count).collect();
    (c, d)
}

impl Cluster for MpiCluster {
    fn rank(&self) -> u32 {
        self.comm.rank() as u32
    }
    fn size(&self) -> u32 {
        self.comm.size() as u32
    }
    fn exchange(&mut self, peers: &[u32], out: &[Vec<f64>], inbox: &mut [Vec<f64>]) {
        let clock = WaitClock::start();
        let comm = &self.comm;
        mpi::request::scope(|sc| {
            let sends: Vec<_> = peers
                .iter()
                .zip(out)
                .map(|(&p, o)| comm.process_at_rank(p as i32).immediate_send_with_tag(sc, &o[..], TAG))
                .collect();
            for (&p, b) in peers.iter().zip(inbox.iter_mut()) {
                let (msg, status) = comm.process_at_rank(p as i32).matched_probe_with_tag(TAG);
                let n = status.count(f64::equivalent_datatype()) as usize;
                b.clear();
                b.resize(n, 0.0);
                msg.matched_receive_into(&mut b[..]);
            }
            for r in sends {
                r.wait();
            }
        });
        clock.stop(&mut self.wait);
    }
    fn all_to_all(&mut self, to: &[u64], from: &mut Vec<u64>) {
        let clock = WaitClock::start();
        from.clear();
        from.resize(to.len(), 0);
        self.comm.all_to_all_into(to, &mut from[..]);
        clock.stop(&mut self.wait);
    }
    fn all_gather(&mut self, mine: &[f64], counts: &[usize], all: &mut Vec<f64>) {
        let clock = WaitClock::start();
        let (c, d) = counts_displs(counts);
        all.clear();
        all.resize(counts.iter().sum(), 0.0);
        let mut part = PartitionMut::new(&mut all[..], c, d);
        self.comm.all_gather_varcount_into(mine, &mut part);
        clock.stop(&mut self.wait);
    }
    fn gather(&mut self, mine: &[f64], counts: &[usize], all: &mut Vec<f64>) {
        let clock = WaitClock::start();
        let root = self.comm.process_at_rank(0);
        if self.comm.rank() == 0 {
            let (c, d) = counts_displs(counts);
            all.clear();
            all.resize(counts.iter().sum(), 0.0);
            let mut part = PartitionMut::new(&mut all[..], c, d);
            root.gather_varcount_into_root(mine, &mut part);
        } else {
            root.gather_varcount_into(mine);
        }
        clock.stop(&mut self.wait);
    }
    fn scatter(&mut self, all: &[f64], counts: &[usize], mine: &mut Vec<f64>) {
        let clock = WaitClock::start();
        let root = self.comm.process_at_rank(0);
        mine.clear();
        mine.resize(counts[self.comm.rank() as usize], 0.0);
        if self.comm.rank() == 0 {
            let (c, d) = counts_displs(counts);
            let part = Partition::new(all, c, d);
            root.scatter_varcount_into_root(&part, &mut mine[..]);
        } else {
            root.scatter_varcount_into(&mut mine[..]);
        }
        clock.stop(&mut self.wait);
    }
    fn min_max(&mut self, x: u64) -> (u64, u64) {
        let clock = WaitClock::start();
        let (mut lo, mut hi) = (0u64, 0u64);
        self.comm.all_reduce_into(&x, &mut lo, mpi::collective::SystemOperation::min());
        self.comm.all_reduce_into(&x, &mut hi, mpi::collective::SystemOperation::max());
        clock.stop(&mut self.wait);
        (lo, hi)
    }
    fn waited(&self) -> (f64, f64) {
        self.wait
    }
    fn abort(&self, code: i32) -> ! {
        self.comm.abort(code)
    }
}
