#!/usr/bin/env bash
# Installs the Debian 12 packages SphereKit builds, runs and tests with. Idempotent: it asks
# apt only for what is missing, and refreshes the package lists only then. Non-interactive.
#   bash scripts/install_deps.sh          build + the main job (scripts/run.sh)
#   bash scripts/install_deps.sh --test   also what the tests need (scripts/test.sh)
set -euo pipefail

with_tests=0
for arg in "$@"; do
  case "$arg" in
    --test) with_tests=1 ;;
    -h|--help) sed -n '2,5p' "$0"; exit 0 ;;
    *) echo "install_deps: unknown argument '$arg' (only --test)" >&2; exit 2 ;;
  esac
done

# OpenMesh is not used: libparam has its own half-edge code (Debian's libopenmesh-dev also
# pulls in ~190 MB of OpenSceneGraph/GDAL dependencies).
packages=(
  cmake g++ ninja-build pkg-config
  libeigen3-dev nlohmann-json3-dev libcli11-dev catch2 zlib1g-dev
  libosd-dev libopenexr-dev libtinygltf-dev libdraco-dev libmeshoptimizer-dev libstb-dev
  # the Python module (python/): pybind11 and the interpreter's headers; numpy arrays in and out
  python3-dev python3-pybind11 python3-numpy python3-scipy
)
# The results page's 3-D viewer (scripts/setup_viewer.sh bundles three.js from npm) needs node
# and npm: Debian's, unless a node with its npm is on PATH already (e.g. NodeSource's nodejs,
# which bundles npm and conflicts with Debian's npm package).
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  packages+=(nodejs npm)
fi
# npm fetches over https: Debian's node uses the system's certificate store.
packages+=(ca-certificates)
if [[ "$with_tests" == 1 ]]; then
  # pytest for python/tests; Chromium for the results page's browser test; dpkg-dev and file
  # for the Debian package's dependency scan (CPack runs dpkg-shlibdeps on every ELF file).
  packages+=(python3-pytest chromium dpkg-dev file)
fi

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

# Another package manager at work (a second set-up script, the reference's build script, the
# system's unattended upgrades) holds dpkg's locks, and apt-get then fails at once ("Could not
# get lock /var/lib/dpkg/lock-frontend", seen on a new machine with the reference being built
# beside this script): wait for it, up to 10 minutes, then let apt itself wait for the lock
# (DPkg::Lock::Timeout) for the race between the check and the call.
for ((waited = 0; waited < 600; waited += 5)); do
  pgrep -x 'apt|apt-get|dpkg|unattended-upgr' >/dev/null 2>&1 || break
  [[ $waited -eq 0 ]] && echo "install_deps: waiting for another apt/dpkg process to finish" >&2
  sleep 5
done
echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${SUDO[@]}" apt-get update -qq
"${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
  -o DPkg::Lock::Timeout=600 "${missing[@]}" </dev/null
