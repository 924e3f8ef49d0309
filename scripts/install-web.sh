#!/usr/bin/env bash
# Installs the npm packages of featsense view's tile-set page (three.js and 3d-tiles-renderer,
# viewer_export/web/npm/package.json) where they are missing. The rest of the viewer needs
# only Debian's libjs-three; without these, `featsense view` on a tile set says how to get them.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
modules="$root/viewer_export/web/npm"
if [ -d "$modules/node_modules/three" ] && [ -d "$modules/node_modules/3d-tiles-renderer" ]; then
  exit 0
fi
if ! command -v npm >/dev/null; then
  echo "warning: npm is not installed; featsense view cannot show tile sets" >&2
  exit 0
fi
(cd "$modules" && npm install --no-audit --no-fund --silent --no-package-lock) ||
  echo "warning: npm install in viewer_export/web/npm failed; featsense view cannot show tile sets" >&2
