#!/usr/bin/env bash
# Installs what is missing (Debian packages), builds everything and runs all tests.
# Usage: bash scripts/test.sh [extra cmake arguments]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/install-deps.sh"
build="${FEATSENSE_BUILD_DIR:-$root/build}"
cmake -S "$root" -B "$build" -G Ninja -DFEATSENSE_BUILD_TESTS=ON "$@"
cmake --build "$build" --parallel "$(nproc)"
cd "$build"
ctest --output-on-failure --parallel "$(nproc)" --timeout 300
