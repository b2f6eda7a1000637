#!/usr/bin/env bash
# Installs what the tests need and runs every test (the README's test command).
# Today the tests need only the Rust toolchain: the default build uses no MPI and no
# Python. The MPI transport and the deformable-body plugin will add their Debian
# packages and the Python virtualenv here when they land.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v cargo >/dev/null 2>&1; then
  echo "cargo is required: install Rust from https://rustup.rs" >&2
  exit 1
fi
# Physics tests run in release mode (heavy); everything else runs there too so that
# the workspace is built once.
cargo test --workspace --release --no-fail-fast
