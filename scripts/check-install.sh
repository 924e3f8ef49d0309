#!/usr/bin/env bash
# Installs the built libraries into a fresh prefix and builds and runs the example that
# embeds the Mapper (docs/examples/embed) against it, as another project would.
# Usage: bash scripts/check-install.sh [BUILD_DIR]   (default: build/, already built)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="${1:-${FEATSENSE_BUILD_DIR:-$root/build}}"
work=$(mktemp -d "${TMPDIR:-/tmp}/featsense-install.XXXXXX")
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
cmake -S "$root/docs/examples/embed" -B "$work/embed" -G Ninja \
  -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release > "$work/configure.log"
cmake --build "$work/embed" --parallel "$(nproc)" > "$work/build.log"
"$work/embed/featsense_embed" "$work/out" | tail -n 3
for file in map.h5 mesh.ply; do
  [ -s "$work/out/$file" ] || { echo "check-install: the example wrote no $file" >&2; exit 1; }
done
echo "check-install: the installed package builds the example, which mapped and meshed"
