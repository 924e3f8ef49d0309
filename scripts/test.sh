#!/usr/bin/env bash
# Installs what is missing (Debian packages), builds everything and runs all tests.
# Usage: bash scripts/test.sh [extra cmake arguments]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/install-web.sh"
# The glTF tests run the Khronos validator, and the browser tests (report.html, the viewer)
# drive Debian's Chromium with playwright-core, where they can be installed; where either
# install fails, the tests that need it skip with a message.
tools="$root/test/tools"
if command -v npm >/dev/null &&
  { [ ! -d "$tools/node_modules/gltf-validator" ] || [ ! -d "$tools/node_modules/playwright-core" ]; }; then
  (cd "$tools" && npm install --no-audit --no-fund --silent) ||
    echo "warning: npm install in test/tools failed; the glTF validator and browser checks will be skipped"
fi
if ! command -v chromium >/dev/null; then
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends chromium ||
    echo "warning: chromium not installed; the browser tests will be skipped"
fi
build="${FEATSENSE_BUILD_DIR:-$root/build}"
# A build with its tests takes about 3.5 GB (objects with debug information); a disk that
# fills halfway fails at some link with "No space left on device". Say so before it starts.
need_kb=$((3500 * 1024))
[ -d "$build" ] && need_kb=$((need_kb - $(du -sk "$build" | cut -f1)))
parent="$build"
while [ ! -d "$parent" ]; do parent=$(dirname "$parent"); done
free_kb=$(df -Pk "$parent" | awk 'NR == 2 { print $4 }')
if [ "$need_kb" -gt 0 ] && [ "$free_kb" -lt "$need_kb" ]; then
  echo "scripts/test.sh: $((free_kb / 1024)) MB free on the disk of $build;" \
    "the build and its tests need about $((need_kb / 1024)) MB more" >&2
  exit 1
fi
cmake -S "$root" -B "$build" -G Ninja -DFEATSENSE_BUILD_TESTS=ON "$@"
cmake --build "$build" --parallel "$(nproc)"
cd "$build"
ctest --output-on-failure --parallel "$(nproc)" --timeout 300
