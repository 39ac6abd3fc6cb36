#!/usr/bin/env bash
# Installs and builds the 3-D viewer of the results page (`spherekit run` writes OUT/index.html)
# into a folder outside the repository. From npm: three.js, bundled by esbuild with its glTF
# loader and orbit controls into ONE classic script (global THREE), and Google's JavaScript
# (asm.js) Draco decoder as three ships it. Classic scripts and no WebAssembly, because the page
# must also work opened from disk (file://), where Chromium refuses ES modules, fetch and XHR.
# `spherekit` copies DIR/dist into each results folder (OUT/site/lib); without it the page
# shows everything but the 3-D views and says why.
#   bash scripts/setup_viewer.sh [DIR] [--browser] [--install-chromium]
#     DIR                 default $SPHEREKIT_VIEWER_DIR, else ~/.cache/spherekit/viewer
#     --browser           also what the page's browser test needs: playwright-core (npm) and
#                         Debian's Chromium at $CHROMIUM (default /usr/bin/chromium)
#     --install-chromium  with --browser: apt-get install chromium when it is missing
# Idempotent: when the pinned versions are present it only prints DIR (no network). Concurrent
# runs wait for each other (flock on DIR/.lock). Prints DIR on stdout when ready.
# Exit: 0 ready; 3 node/npm/Chromium missing or an install failed (the tests skip with this message).
set -euo pipefail

dir=""
browser=0
install_chromium=0
for arg in "$@"; do
  case "$arg" in
    --browser) browser=1 ;;
    --install-chromium) install_chromium=1 ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    -*) echo "setup_viewer: unknown option '$arg'" >&2; exit 2 ;;
    *) dir="$arg" ;;
  esac
done
dir="${dir:-${SPHEREKIT_VIEWER_DIR:-$HOME/.cache/spherekit/viewer}}"
chromium="${CHROMIUM:-/usr/bin/chromium}"

# Pinned, so that every results folder gets the viewer the page was tested with.
three_version=0.187.0
packages=(three@$three_version esbuild@0.28.2)
# playwright-core 1.61.1: the last release that runs on Debian 12's Node.js 18 (1.62 and later
# refuse it: "Playwright requires Node.js 20 or higher"); it drives Debian's Chromium 156.
if [[ "$browser" == 1 ]]; then packages+=(playwright-core@1.61.1); fi

if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  echo "setup_viewer: node and npm are not installed (e.g. apt-get install nodejs npm)" >&2
  exit 3
fi

if [[ "$browser" == 1 && ! -x "$chromium" ]]; then
  if [[ "$install_chromium" == 1 ]]; then
    sudo=()
    if [[ "$(id -u)" -ne 0 ]]; then
      if command -v sudo >/dev/null 2>&1; then sudo=(sudo); fi
    fi
    echo "setup_viewer: installing Debian's chromium (apt-get)" >&2
    # Failing here is not fatal for the caller: the browser test then skips with the message below.
    "${sudo[@]}" apt-get update -qq >&2 || true
    "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends -o DPkg::Lock::Timeout=600 chromium \
      </dev/null >&2 || true
  fi
  if [[ ! -x "$chromium" ]]; then
    echo "setup_viewer: Chromium is not installed at $chromium (apt-get install chromium)" >&2
    exit 3
  fi
fi

# shellcheck source=npm_pinned.sh
source "$(dirname "${BASH_SOURCE[0]}")/npm_pinned.sh"
npm_pinned_install setup_viewer spherekit-viewer "$dir" "${packages[@]}"

# The bundle: rebuilt when absent or made from other versions. Built beside dist/ and renamed
# into place, so a results folder never copies a half-written viewer.
stamp="three $three_version, esbuild $(npm_installed_version "$dir" esbuild), bundle v1"
if [[ ! -f "$dir/dist/STAMP" || "$(cat "$dir/dist/STAMP")" != "$stamp" ]]; then
  echo "setup_viewer: bundling three.js $three_version into $dir/dist" >&2
  tmp="$dir/dist.tmp"
  rm -rf "$tmp"
  mkdir -p "$tmp"
  cat >"$dir/viewer_entry.mjs" <<'EOF'
export * from 'three';
export { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
export { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
EOF
  if ! "$dir/node_modules/.bin/esbuild" "$dir/viewer_entry.mjs" --bundle --format=iife --global-name=THREE \
      --minify --legal-comments=eof --log-level=warning --outfile="$tmp/three-viewer.js" >&2; then
    echo "setup_viewer: esbuild could not bundle three.js" >&2
    exit 3
  fi
  cp "$dir/node_modules/three/examples/jsm/libs/draco/draco_decoder.js" "$tmp/draco_decoder.js"
  cp "$dir/node_modules/three/LICENSE" "$tmp/LICENSE-three.js.txt"
  cat >"$tmp/NOTICE.txt" <<EOF
Third-party scripts of this page, installed from npm by SphereKit's scripts/setup_viewer.sh:
  three-viewer.js   three.js $three_version (three, examples/jsm GLTFLoader and OrbitControls),
                    bundled by esbuild; MIT license, see LICENSE-three.js.txt.
  draco_decoder.js  Google's Draco decoder compiled to JavaScript, as shipped by three $three_version
                    (examples/jsm/libs/draco); Apache License 2.0.
EOF
  echo "$stamp" >"$tmp/STAMP"
  rm -rf "$dir/dist.old"
  if [[ -d "$dir/dist" ]]; then mv "$dir/dist" "$dir/dist.old"; fi
  mv "$tmp" "$dir/dist"
  rm -rf "$dir/dist.old"
fi
echo "$dir"
