#!/usr/bin/env bash
# The main job on a fresh machine: installs what is missing, builds featsense and runs its
# demo: a built-in scene simulated, mapped, meshed and compared with the truth.
# Usage: bash scripts/demo.sh [arguments for featsense demo, e.g. --scene parking -o DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/install-web.sh"
build="${FEATSENSE_BUILD_DIR:-$root/build}"
cmake -S "$root" -B "$build" -G Ninja > /dev/null
cmake --build "$build" --parallel "$(nproc)" --target featsense
"$build/app/featsense" demo "$@"
