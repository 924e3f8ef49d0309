#!/usr/bin/env bash
# Installs what is missing (Debian packages), builds everything and runs all tests.
# Usage: bash scripts/test.sh [extra cmake arguments]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/install-deps.sh"
# The glTF tests run the Khronos validator where node has it; a failed install only skips them.
if command -v npm >/dev/null && [ ! -d "$root/test/tools/node_modules/gltf-validator" ]; then
  (cd "$root/test/tools" && npm install --no-audit --no-fund --silent) ||
    echo "warning: gltf-validator not installed; the glTF validator checks will be skipped"
fi
build="${FEATSENSE_BUILD_DIR:-$root/build}"
cmake -S "$root" -B "$build" -G Ninja -DFEATSENSE_BUILD_TESTS=ON "$@"
cmake --build "$build" --parallel "$(nproc)"
cd "$build"
ctest --output-on-failure --parallel "$(nproc)" --timeout 300
