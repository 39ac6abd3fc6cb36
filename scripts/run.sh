#!/usr/bin/env bash
# The main job on a fresh Debian 12 machine: install what is missing, build, and run
# `spherekit run`. Without arguments it maps the built-in samples and writes ./spherekit-out;
# with arguments they are passed on (meshes, -o OUT_DIR, --effort N, ...).
#   bash scripts/run.sh
#   bash scripts/run.sh ../shared/meshes/spot.obj -o out
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

bash "$root/scripts/install_deps.sh"
bash "$root/scripts/build.sh"
# three.js and the Draco decoder for the results page's 3-D view (npm): optional, without them
# index.html shows everything else and says why.
bash "$root/scripts/setup_viewer.sh" >/dev/null || true
exec "$root/build/tools/cli/spherekit" run "$@"
