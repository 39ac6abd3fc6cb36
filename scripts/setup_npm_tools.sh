#!/usr/bin/env bash
# Installs the npm tools the glTF tests run (Khronos gltf-validator, Google's draco3d decoder,
# gltfpack for the meshopt reader test)
# into a folder outside the repository. Idempotent: when the pinned versions are present it
# prints their folder and touches nothing else (no network). Concurrent runs wait for each
# other (flock on DIR/.lock).
#   bash scripts/setup_npm_tools.sh [DIR] [--compare]
#     DIR        default $SPHEREKIT_NPM_DIR, else ~/.cache/spherekit/npm-tools
#     --compare  also the size-comparison peer @gltf-transform/cli (not needed by the tests)
# Exit: 0 ready; 3 node/npm missing or the install failed (the tests skip with this message).
set -euo pipefail

dir=""
compare=0
for arg in "$@"; do
  case "$arg" in
    --compare) compare=1 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    -*) echo "setup_npm_tools: unknown option '$arg'" >&2; exit 2 ;;
    *) dir="$arg" ;;
  esac
done
dir="${dir:-${SPHEREKIT_NPM_DIR:-$HOME/.cache/spherekit/npm-tools}}"

# Pinned: the versions ECOSYSTEM.md validated (0 errors/0 warnings on Draco .glb).
packages=(gltf-validator@2.0.0-dev.3.10 draco3d@1.5.9 gltfpack@1.3.0)
if [[ "$compare" == 1 ]]; then packages+=(@gltf-transform/cli@4.5.1); fi

if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  echo "setup_npm_tools: node and npm are not installed (e.g. apt-get install nodejs npm)" >&2
  exit 3
fi

# shellcheck source=npm_pinned.sh
source "$(dirname "${BASH_SOURCE[0]}")/npm_pinned.sh"
npm_pinned_install setup_npm_tools spherekit-npm-tools "$dir" "${packages[@]}"
echo "$dir"
