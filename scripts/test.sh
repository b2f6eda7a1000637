#!/usr/bin/env bash
# Installs what the tests need and runs every test (the README's test command).
#   - Debian's libhdf5-dev (FCLIB problem files, cargo feature `hdf5`)
# The default build (`cargo run`) needs none of it: no MPI, no Python, no HDF5.
# MPI and the Python virtualenv of the deformable bodies join here when they land.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v cargo >/dev/null 2>&1; then
  echo "cargo is required: install Rust from https://rustup.rs" >&2
  exit 1
fi
need=()
for pkg in libhdf5-dev pkg-config; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${need[@]}"
fi
# Physics tests run in release mode (heavy); everything else runs there too so that
# the workspace is built once.
cargo test --workspace --release --no-fail-fast --features nscdd-cli/hdf5,nscdd-tests/hdf5
