#!/usr/bin/env bash
# Installs what the tests need and runs every test (the README's test command).
#   - Debian's libhdf5-dev (FCLIB problem files, cargo feature `hdf5`)
#   - OpenMPI (libopenmpi-dev, openmpi-bin) and libclang-dev (rsmpi's bindings),
#     cargo feature `mpi`: the MPI tests run `mpirun` with oversubscription
# The default build (`cargo run`) needs none of it: no MPI, no Python, no HDF5.
#   - a Python virtualenv ./venv with scikit-fem and meshio (deformable bodies, cargo
#     feature `fem`); Debian's python3-venv and python3-dev if Python cannot make one;
#     the nscdd Python module (python/, maturin) and pytest are installed in it
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v cargo >/dev/null 2>&1; then
  echo "cargo is required: install Rust from https://rustup.rs" >&2
  exit 1
fi
need=()
for pkg in libhdf5-dev pkg-config libopenmpi-dev openmpi-bin libclang-dev; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${need[@]}"
fi
# Python 3 with venv and a shared libpython (pyenv's, or Debian's python3-dev)
if ! python3 -c "import venv, ensurepip, sysconfig; assert sysconfig.get_config_var('Py_ENABLE_SHARED')" >/dev/null 2>&1; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q python3 python3-venv python3-dev
fi
if ! venv/bin/python -c "import skfem, meshio" >/dev/null 2>&1; then
  python3 -m venv venv
  venv/bin/pip install -q scikit-fem meshio
fi
# pyo3 builds against the virtualenv's Python; at run time nscdd finds scikit-fem there
export PYO3_PYTHON="$PWD/venv/bin/python" NSCDD_PYTHON_ENV="$PWD/venv"
# Physics tests run in release mode (heavy); everything else runs there too so that
# the workspace is built once.
# OpenMPI refuses to run as root unless told; the MPI tests also set these.
# Containers often forbid the cross-memory attach OpenMPI uses for large messages.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none
cargo test --workspace --release --no-fail-fast --features nscdd-cli/hdf5,nscdd-tests/hdf5,nscdd-cli/mpi,nscdd-cli/fem,nscdd-fuzz/fem,nscdd-fuzz/hdf5
# The Python module (python/, docs/PYTHON.md): built by maturin into the
# virtualenv (reusing target/), then its pytest suite (which compares a run with
# target/release/nscdd's, built above).
venv/bin/pip install -q pytest ./python
# ... and built again with the polygons plugin in one cargo command: run-time
# plugins loaded from Python (python/tests' plugin test)
bash scripts/python_with_plugins.sh nscdd-polygons
venv/bin/python -m pytest -q python/tests
# Fuzzing, bounded (docs/RELIABILITY.md): every target 20 s on mutants of its corpus
# (tests/fuzz/corpus); a panic or a hang fails the run, its input saved in
# target/fuzz-failures/. The binary was built by the tests above.
target/release/nscdd-fuzz --seconds 20
