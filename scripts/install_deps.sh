#!/usr/bin/env bash
# Installs the Debian 12 packages SphereKit builds and tests with. Idempotent: it asks apt
# only for what is missing, and refreshes the package lists only then. Non-interactive.
set -euo pipefail

# OpenMesh is not used: libparam has its own half-edge code (Debian's libopenmesh-dev also
# pulls in ~190 MB of OpenSceneGraph/GDAL dependencies).
packages=(
  cmake g++ ninja-build pkg-config
  libeigen3-dev nlohmann-json3-dev libcli11-dev catch2
  libosd-dev libopenexr-dev libtinygltf-dev libdraco-dev libstb-dev libtbb-dev
  python3-numpy python3-scipy
)

missing=()
for p in "${packages[@]}"; do
  # dpkg-query prints "install ok installed" only for fully installed packages.
  if [[ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)" != "install ok installed" ]]; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=()
if [[ "$(id -u)" -ne 0 ]]; then
  if ! command -v sudo >/dev/null 2>&1; then
    echo "install_deps: missing packages (${missing[*]}) and not root, no sudo" >&2
    exit 1
  fi
  SUDO=(sudo)
fi

echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${SUDO[@]}" apt-get update -qq
"${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" </dev/null
