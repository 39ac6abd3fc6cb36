#!/usr/bin/env bash
# Configures and builds SphereKit (Release, Ninja). Idempotent: reruns only rebuild what
# changed.   bash scripts/build.sh              -> build/
#            bash scripts/build.sh --sanitize   -> build-asan/ (ASan + UBSan)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

build_dir=build
cmake_args=(-G Ninja -DCMAKE_BUILD_TYPE=Release)
for arg in "$@"; do
  case "$arg" in
    # -O1 -g1 (line tables only): what ASan recommends, and about half the compile time of
    # RelWithDebInfo, which keeps the CI under its 20 minutes on 2 cores.
    --sanitize) build_dir=build-asan; cmake_args=(-G Ninja -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -g1" -DSPHEREKIT_SANITIZE=ON) ;;
    -h|--help) sed -n '2,5p' "$0"; exit 0 ;;
    *) echo "build.sh: unknown argument '$arg' (only --sanitize)" >&2; exit 2 ;;
  esac
done

# Two jobs: the machines have two cores, and CLI11/Eigen translation units need ~1 GB each.
jobs="${SPHEREKIT_JOBS:-$(nproc 2>/dev/null || echo 2)}"

cmake -S . -B "$build_dir" "${cmake_args[@]}" >/dev/null
cmake --build "$build_dir" -j "$jobs"
echo "build.sh: built in $build_dir/"
