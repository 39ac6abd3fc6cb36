#!/usr/bin/env bash
# Installs Debian's Blender (3.4 on Debian 12) for the test that loads a cage + displacement
# texture into it (tests/convert/blender_cage_test.cpp, scripts/blender_setup_cage.py).
# Optional: without it that test skips with a message. Measured on the 2-core CI machine:
# 51 s for apt-get install --no-install-recommends blender (166 MB of packages, half of them already in the apt cache).
#   bash scripts/setup_blender.sh
# Exit: 0 Blender runs; 3 it could not be installed.
set -euo pipefail

if ! command -v blender >/dev/null 2>&1; then
  sudo=()
  if [[ "$(id -u)" -ne 0 ]] && command -v sudo >/dev/null 2>&1; then sudo=(sudo); fi
  echo "setup_blender: installing Debian's blender (apt-get)" >&2
  "${sudo[@]}" apt-get update -qq >&2 || true
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends -o DPkg::Lock::Timeout=600 blender \
    </dev/null >&2 || true
fi
if ! blender --version >/dev/null 2>&1; then
  echo "setup_blender: blender is not installed and could not be (apt-get install --no-install-recommends blender)" >&2
  exit 3
fi
blender --version 2>/dev/null | head -1
