#!/usr/bin/env bash
# Sweeps tolerance × decomposition × sweeps per gluing; writes docs/TRADEOFF.md, tradeoff.csv and tradeoff.png.
#   scripts/tradeoff_study.sh [--eps1 0.02] [--tols 1e-2,1e-3,1e-4,1e-5,1e-6] [--decompositions 1x1,2x2,4x4] [--sweeps 1,4]
# About 1 h 40 min of CPU on this machine (the runs at 1e-5 and 1e-6 reach max_sweeps); runs are cached in out/tradeoff.
# Needs a Python 3 with venv; installs matplotlib in .venv-docs on first use.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x .venv-docs/bin/python ]; then
  python3 -m venv .venv-docs
  .venv-docs/bin/pip install -q matplotlib
fi
cargo build --release --bin nscdd
.venv-docs/bin/python scripts/tradeoff_study.py "$@"
