#!/usr/bin/env bash
# Sweeps tolerance × solver × decomposition × sweeps per gluing over three scenes (2D biaxial test,
# 3D triaxial test, brick-wall pushover); writes docs/TRADEOFF.md, docs/tradeoff.csv and
# docs/tradeoff_<scene>.png.
#   scripts/tradeoff_study.sh [--scenes biaxial,triaxial,wall] [--tols 1e-2,1e-3,1e-4,1e-5,1e-6] [--methods nlgs,anderson,newton]
# About 1 h 15 min of CPU on this machine (Newton and the runs at 1e-5 and 1e-6 take most);
# runs are cached in out/tradeoff (delete a run's directory to redo it).
# Needs a Python 3 with venv; installs matplotlib in .venv-docs on first use.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x .venv-docs/bin/python ]; then
  python3 -m venv .venv-docs
  .venv-docs/bin/pip install -q matplotlib
fi
cargo build --release --bin nscdd
.venv-docs/bin/python scripts/tradeoff_study.py "$@"
