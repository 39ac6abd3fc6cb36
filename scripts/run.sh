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
# three.js and the Draco decoder for the results page's 3-D views (npm). The job runs without
# them, but the page then lacks its 3-D views: say so before the run and again after it, so
# the reason is not lost in the build and progress output.
viewer_note=""
viewer_log="$(mktemp)"
viewer_status=0
bash "$root/scripts/setup_viewer.sh" >/dev/null 2>"$viewer_log" || viewer_status=$?
cat "$viewer_log" >&2
if [[ "$viewer_status" != 0 ]]; then
  viewer_note="$(tail -1 "$viewer_log")"
  viewer_note="${viewer_note:-setup_viewer.sh failed (exit $viewer_status)}"
  echo "run.sh: WARNING: the results page will have no 3-D views: $viewer_note" >&2
fi
rm -f "$viewer_log"
status=0
"$root/build/tools/cli/spherekit" run "$@" || status=$?
if [[ -n "$viewer_note" ]]; then
  echo "run.sh: WARNING: the results page has no 3-D views: $viewer_note (fix it, then run again)" >&2
fi
exit "$status"
