#!/usr/bin/env bash
# Builds the Python module together with run-time plugin crates, in one cargo
# command, and installs it over the module of the virtualenv (docs/PYTHON.md).
#   scripts/python_with_plugins.sh nscdd-polygons [more plugin packages]
# A plugin library is accepted only from the build of the program that loads it
# (the framework compares its types: docs/PLUGINS.md); `pip install ./python`
# builds the module alone, so a plugin built by another cargo command is refused.
# Here both come from one build: the module goes into the virtualenv ($VENV,
# default ./venv), the plugins to target/python/lib<name>.so, for scenes'
# `[[plugins]] library = "target/python/libnscdd_polygons.so"`.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-venv}
if [ $# -lt 1 ]; then
  echo "usage: $0 PLUGIN_PACKAGE..." >&2
  exit 2
fi
"$VENV/bin/python" -c "import nscdd" 2>/dev/null || "$VENV/bin/pip" install -q ./python
pkgs=()
libs=()
for p in "$@"; do
  pkgs+=(-p "$p")
  libs+=("lib${p//-/_}.so")
done
# cargo writes a cdylib under the same name whatever the features: the libraries
# other builds made (the command line's, its tests') are put back afterwards
keep=$(mktemp -d)
for l in "${libs[@]}"; do
  for d in target/release target/release/deps; do
    [ -e "$d/$l" ] && mkdir -p "$keep/$d" && cp -p "$d/$l" "$keep/$d/$l"
  done
done
PYO3_PYTHON="$PWD/$VENV/bin/python" PYO3_BUILD_EXTENSION_MODULE=1 \
  cargo build --release --quiet -p nscdd-python --features nscdd-python/fem "${pkgs[@]}"
mkdir -p target/python
for l in "${libs[@]}"; do
  cp target/release/$l target/python/$l
  for d in target/release target/release/deps; do
    if [ -e "$keep/$d/$l" ]; then cp -p "$keep/$d/$l" "$d/$l"; fi
  done
done
rm -rf "$keep"
dest=$("$VENV/bin/python" -c "import nscdd, os, sysconfig; print(os.path.join(os.path.dirname(nscdd.__file__), '_nscdd' + sysconfig.get_config_var('EXT_SUFFIX')))")
cp target/release/lib_nscdd.so "$dest"
echo "installed $dest; the plugins built with it: ${libs[*]/#/target/python/}"
