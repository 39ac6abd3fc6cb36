#!/usr/bin/env bash
# Installation tests (issue 24), run by ctest from tests/install/CMakeLists.txt:
#   install_test.sh downstream BUILD_DIR SOURCE_DIR VERSION
#       cmake --install BUILD_DIR into a scratch prefix; check the installed tree; build the
#       downstream project (tests/install/downstream: find_package(SphereKit), SphereKit::param
#       and SphereKit::convert) and the same program through pkg-config; run them.
#   install_test.sh subproject BUILD_DIR SOURCE_DIR VERSION
#       configure tests/install/subproject (SphereKit through add_subdirectory) with an empty
#       and with a set build type; the parent's must survive.
#   install_test.sh deb BUILD_DIR SOURCE_DIR VERSION
#       cpack the Debian packages; check that every Depends of spherekit_VERSION_amd64.deb is
#       installed or installable here (dpkg-query / apt-cache policy); extract it into a scratch
#       root (dpkg -x) and run its spherekit (`run` on two small samples) and Python module from
#       there. A real `apt-get install ./spherekit_*.deb` on a clean Debian 12 root is
#       scripts/check_minimal_root.sh (needs root and a few minutes; not run by ctest).
# Scratch files go to BUILD_DIR/tests/install-MODE (replaced on each run). Exit 0 pass, 1 fail,
# 77 skipped (printed reason).
set -euo pipefail
mode="$1" build="$(cd "$2" && pwd)" src="$(cd "$3" && pwd)" version="$4"
here="$src/tests/install"
work="$build/tests/install-$mode"
rm -rf "$work"
mkdir -p "$work"
fail() { echo "install_test: FAILED: $*" >&2; exit 1; }
skip() { echo "SPHEREKIT-SKIP: $*"; exit 77; }
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi

case "$mode" in
downstream)
  prefix="$work/prefix"
  cmake --install "$build" --prefix "$prefix" >"$work/install.log" || { cat "$work/install.log"; fail "cmake --install"; }
  echo "install_test: installed $(grep -c '^-- Installing' "$work/install.log") files into $prefix"
  libdir="$(cd "$prefix" && find . -name 'libspherekit_param.a' -printf '%h\n' | head -1)"
  [[ -n "$libdir" ]] || fail "no libspherekit_param.a under $prefix"
  for f in bin/spherekit \
           "$libdir"/libspherekit_{param,formats,samples,convert}.a \
           include/spherekit/{sphere_param.h,status.h,version.h,formats/mesh_io.h,convert/gltf_lods.h,samples/sample_collection.h} \
           "$libdir"/cmake/SphereKit/{SphereKitConfig.cmake,SphereKitConfigVersion.cmake,SphereKitTargets.cmake,FindOpenSubdiv.cmake} \
           "$libdir"/pkgconfig/spherekit.pc; do
    [[ -e "$prefix/$f" ]] || fail "not installed: $f"
  done
  # Internal headers (src/, detail/) stay private.
  if find "$prefix/include" -path '*detail*' | grep -q .; then fail "a detail header was installed"; fi
  "$prefix/bin/spherekit" --version | grep -qF "$version" || fail "installed spherekit --version does not say $version"
  grep -qF "\"$version\"" "$prefix/include/spherekit/version.h" || fail "installed version.h does not say $version"

  # CMake: find_package(SphereKit <version> EXACT), both executables built and run.
  cmake -S "$here/downstream" -B "$work/build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$prefix" -DEXPECTED_VERSION="$version" >"$work/configure.log" 2>&1 \
    || { cat "$work/configure.log"; fail "configuring the downstream project"; }
  cmake --build "$work/build" -j 2 >"$work/build.log" 2>&1 || { cat "$work/build.log"; fail "building the downstream project"; }
  "$work/build/downstream_param" || fail "downstream_param"
  "$work/build/downstream_convert" "$work" || fail "downstream_convert"
  # A version the package is not compatible with must be refused.
  if cmake -S "$here/downstream" -B "$work/build-wrong" "${generator[@]}" -DCMAKE_PREFIX_PATH="$prefix" \
       -DEXPECTED_VERSION=99.0.0 >"$work/wrong.log" 2>&1; then
    fail "find_package(SphereKit 99.0.0 EXACT) succeeded"
  fi
  grep -qF "version: $version" "$work/wrong.log" \
    || { cat "$work/wrong.log"; fail "the version refusal does not name the installed version"; }
  echo "install_test: find_package(SphereKit 99.0.0) refused, as it should"

  # pkg-config: the same program, param only, compiled and linked from the .pc file alone.
  export PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig"
  [[ "$(pkg-config --modversion spherekit)" == "$version" ]] || fail "pkg-config --modversion spherekit"
  # shellcheck disable=SC2046  # pkg-config prints a list of flags
  ${CXX:-c++} -std=c++20 -O1 -o "$work/downstream_pc" "$here/downstream/main.cpp" -DEXPECTED_VERSION="\"$version\"" \
    $(pkg-config --cflags --libs spherekit) || fail "compiling with pkg-config --cflags --libs spherekit"
  "$work/downstream_pc" || fail "downstream_pc"
  ;;
subproject)
  for build_type in "" Debug; do
    cmake -S "$here/subproject" -B "$work/build-${build_type:-empty}" "${generator[@]}" \
      -DSPHEREKIT_SOURCE_DIR="$src" -DCMAKE_BUILD_TYPE="$build_type" >"$work/configure.log" 2>&1 \
      || { cat "$work/configure.log"; fail "configuring the parent with CMAKE_BUILD_TYPE='$build_type'"; }
    grep "parent:" "$work/configure.log"
    cached="$(sed -n 's/^CMAKE_BUILD_TYPE:[A-Z]*=//p' "$work/build-${build_type:-empty}/CMakeCache.txt")"
    [[ "$cached" == "$build_type" ]] || fail "the parent's cached build type became '$cached' (was '$build_type')"
  done
  ;;
deb)
  for tool in cpack dpkg-deb dpkg-shlibdeps file; do
    command -v "$tool" >/dev/null 2>&1 || skip "$tool is missing (apt-get install dpkg-dev file; scripts/install_deps.sh --test does)"
  done
  cpack --config "$build/CPackConfig.cmake" -B "$work/pkg" >"$work/cpack.log" 2>&1 || { cat "$work/cpack.log"; fail "cpack"; }
  arch="$(dpkg --print-architecture)"
  deb="$work/pkg/spherekit_${version}_${arch}.deb" dev="$work/pkg/spherekit-dev_${version}_${arch}.deb"
  [[ -f "$deb" && -f "$dev" ]] || { ls -l "$work/pkg"; fail "cpack did not make spherekit_${version}_${arch}.deb and spherekit-dev_${version}_${arch}.deb"; }
  depends="$(dpkg-deb -f "$deb" Depends)"
  echo "install_test: $(basename "$deb") ($(du -k "$deb" | cut -f1) KB) Depends: $depends"
  # dpkg-shlibdeps found the libraries the program links (OpenEXR, tinygltf, OpenSubdiv, ...).
  for lib in libopenexr libtinygltf libosdcpu libgomp1 libstdc++6 libc6; do
    grep -q "$lib" <<<"$depends" || fail "Depends lacks $lib (is CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS on?)"
  done
  # Every dependency (one of its alternatives) is installed in a matching version here, or apt
  # has a candidate that matches: what `apt-get install ./spherekit_*.deb` needs.
  IFS=',' read -ra deps <<<"$depends"
  for dep in "${deps[@]}"; do
    ok=0
    IFS='|' read -ra alternatives <<<"$dep"
    for alt in "${alternatives[@]}"; do
      alt="$(echo "$alt" | xargs)"
      name="${alt%% *}" name="${name%%:*}"
      constraint="$(sed -n 's/.*(\(.*\)).*/\1/p' <<<"$alt")"
      for version_here in "$(dpkg-query -W -f='${Version}' "$name" 2>/dev/null || true)" \
                          "$(apt-cache policy "$name" 2>/dev/null | sed -n 's/^ *Candidate: //p' | grep -v '(none)' || true)"; do
        [[ -n "$version_here" ]] || continue
        if [[ -z "$constraint" ]] || dpkg --compare-versions "$version_here" ${constraint%% *} "${constraint#* }"; then ok=1; fi
      done
    done
    [[ "$ok" == 1 ]] || fail "dependency '$(echo "$dep" | xargs)' is neither installed nor installable here"
  done
  echo "install_test: all ${#deps[@]} dependencies are installed or installable"
  dpkg-deb -c "$deb" >"$work/contents.txt"
  grep -q '\./usr/bin/spherekit$' "$work/contents.txt" || fail "the package has no /usr/bin/spherekit"
  grep -q 'usr/lib/python3/dist-packages/spherekit\..*\.so$' "$work/contents.txt" || fail "the package has no Python module"
  dpkg-deb -c "$dev" >"$work/contents-dev.txt"
  grep -q "cmake/SphereKit/SphereKitConfig.cmake$" "$work/contents-dev.txt" || fail "spherekit-dev has no SphereKitConfig.cmake"
  grep -q libeigen3-dev <<<"$(dpkg-deb -f "$dev" Depends)" || fail "spherekit-dev does not depend on libeigen3-dev"

  # The extracted program and module.
  rootfs="$work/root"
  dpkg -x "$deb" "$rootfs"
  "$rootfs/usr/bin/spherekit" --version | grep -qF "$version" || fail "the packaged spherekit --version"
  "$rootfs/usr/bin/spherekit" samples -o "$work/samples" --members 2 --vertices 600 >/dev/null || fail "packaged spherekit samples"
  "$rootfs/usr/bin/spherekit" run "$work/samples/sample_a.obj" "$work/samples/sample_b.obj" -o "$work/out" -q \
    >"$work/run.log" 2>&1 || { cat "$work/run.log"; fail "packaged spherekit run"; }
  for f in report.json index.html collection/collection.json assets/convert_report.json; do
    [[ -s "$work/out/$f" ]] || fail "packaged spherekit run wrote no $f"
  done
  echo "install_test: the packaged spherekit ran the main job on two samples ($work/out)"
  PYTHONPATH="$rootfs/usr/lib/python3/dist-packages" /usr/bin/python3 -c "
import spherekit, sys
assert spherekit.__file__.startswith('$rootfs'), spherekit.__file__
m = spherekit.read_mesh('$work/samples/sample_a.obj')
r = spherekit.param(m, effort=0)
assert r.flipped_faces == 0 and spherekit.__version__ == '$version'
print('install_test: the packaged Python module', spherekit.__version__, 'mapped', m.vertices, 'vertices, 0 flips')
" || fail "the packaged Python module"
  ;;
*) echo "install_test: unknown mode '$mode'" >&2; exit 2 ;;
esac
echo "install_test: $mode passed"
