#!/usr/bin/env bash
# NSCDD on MPI ranks, both schemes, 1/2/4 ranks (docs/PERFORMANCE.md, "MPI").
# Needs OpenMPI (Debian libopenmpi-dev openmpi-bin libclang-dev). Run on a quiet machine.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --features nscdd-cli/hdf5,nscdd-tests/hdf5,nscdd-cli/mpi
python3 scripts/mpi_bench.py "$@"
