#!/usr/bin/env bash
# Reproduces the seed's biaxial study and writes docs/BIAXIAL.md with PNG plots.
#   scripts/biaxial_study.sh [--sizes 2000,12000] [--eps1 0.35] [--eps1-large 0.05]
# Needs a Python 3 with venv; installs matplotlib in .venv-docs on first use.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x .venv-docs/bin/python ]; then
  python3 -m venv .venv-docs
  .venv-docs/bin/pip install -q matplotlib
fi
cargo build --release --bin nscdd
.venv-docs/bin/python scripts/biaxial_study.py "$@"
