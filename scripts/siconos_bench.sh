#!/usr/bin/env bash
# nscdd solve-fc against Siconos' NSGS on the same problems (docs/PERFORMANCE.md,
# "Side by side with Siconos"): a 2D deposit of 6000 disks and a 3D pile of 4000
# spheres (local problems of > 10 000 contacts exported by `nscdd export-fc`) and the
# FCLIB files of tests/data/fclib (converted by `nscdd solve-fc --export-json`).
# Writes one JSON line per problem to out/siconos_bench/results.jsonl.
set -euo pipefail
cd "$(dirname "$0")/.."
need=()
for pkg in python3-siconos python3-scipy libhdf5-dev; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${need[@]}"
fi
cargo build --release --features nscdd-cli/hdf5 --bin nscdd
out=out/siconos_bench
mkdir -p "$out"
bin=target/release/nscdd
[ -f "$out/deposit2d.json.gz" ] || $bin export-fc scripts/bench_scenes/deposit2d.toml --steps 20 --out "$out/deposit2d.json.gz"
[ -f "$out/pile3d.json.gz" ] || $bin export-fc scripts/bench_scenes/pile3d.toml --steps 600 --out "$out/pile3d.json.gz"
for f in tests/data/fclib/*.hdf5; do
  b=$(basename "$f" .hdf5)
  [ -f "$out/$b.json.gz" ] || $bin solve-fc "$f" --max-sweeps 1 --export-json "$out/$b.json.gz" >/dev/null 2>&1
done
: > "$out/results.jsonl"
# the residual each problem reaches in a reasonable number of NLGS sweeps
/usr/bin/python3 scripts/siconos_bench.py --tol 1e-4 "$out/deposit2d.json.gz" | tee -a "$out/results.jsonl"
/usr/bin/python3 scripts/siconos_bench.py --tol 1e-5 "$out/pile3d.json.gz" | tee -a "$out/results.jsonl"
/usr/bin/python3 scripts/siconos_bench.py --tol 1e-6 "$out"/Box_Stacks*.json.gz "$out"/Capsules*.json.gz "$out"/LMGC_100*.json.gz "$out"/Spheres*.json.gz | tee -a "$out/results.jsonl"
