#!/bin/bash
# Strong scaling of NSCDD on a many-core machine (docs/SCALING.md, "Strong scaling on
# 16 real cores"): the seed's 55 006-sphere triaxial (examples/scenes/triaxial55k.toml)
# restarted at step 50, the start of its dense part, for 10 steps, on P MPI ranks and
# T threads; every final.json compared with the one-rank, one-thread file.
#   scripts/strong_scaling.sh prepare      # here: the step-50 state (≈ 20 s), in out/strong
#   scripts/strong_scaling.sh run [D]      # on the many-core machine: D = 4x4x1 by default
# Needs a build with the `mpi` feature (cargo build --release --features nscdd-cli/mpi)
# and mpirun (as root: OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1).
set -euo pipefail
cd "$(dirname "$0")/.."
N=${NSCDD:-$PWD/target/release/nscdd}
S=examples/scenes/triaxial55k.toml
mkdir -p out/strong && cd out/strong
case "${1:-}" in
prepare)
  sed 's/^steps = 500/steps = 50/' ../../$S > s50.toml
  "$N" run s50.toml --out p50 --subdomains 4x4x1 --quiet
  ;;
run)
  D=${2:-4x4x1}
  sed 's/^steps = 500/steps = 60/' ../../$S > s60.toml
  TIMEFORMAT="wall %R s user %U s"
  one() { echo "== $1 ranks x $2 threads, $D"; time mpirun --bind-to none -n "$1" "$N" run s60.toml --restart p50/final.json --out "r$1t$2" --subdomains "$D" --threads "$2" --quiet; }
  for pt in "1 1" "2 1" "4 1" "8 1" "16 1" "1 2" "1 4" "1 8" "1 16" "4 4" "2 8"; do one $pt; done
  for d in r*t*; do cmp -s r1t1/final.json "$d/final.json" && echo "$d: final.json = 1 rank, 1 thread" || echo "$d: DIFFERS"; done
  ;;
*) sed -n 2,9p "$0"; exit 2 ;;
esac
