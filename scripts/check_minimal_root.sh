#!/usr/bin/env bash
# The README's two commands on a minimal Debian 12 root, as a new user would run them (issue 24).
# Needs root (debootstrap, chroot, mounts), network access to the Debian mirror and npm, and
# some minutes (two builds from scratch). CI does not run it.
#   sudo bash scripts/check_minimal_root.sh [WORK_DIR] [--quick] [--ccache DIR] [--keep]
#     WORK_DIR      where the roots go (default /var/tmp/spherekit-minimal-root), replaced
#     --quick       test.sh without its sanitizer build (SPHEREKIT_SKIP_SANITIZE=1)
#     --ccache DIR  share a ccache folder with the roots (faster; the times then are not a new
#                   user's; ccache is installed in the root for it)
#     --keep        leave the roots in place afterwards
# Steps, each timed:
#   1. debootstrap --variant=minbase bookworm (the host's Debian mirror); a pristine copy is kept
#   2. a fresh clone of this repository's HEAD into the root
#   3. bash scripts/run.sh   (in the root: installs the packages, builds, runs the main job;
#      checks the results page got its 3-D viewer)
#   4. bash scripts/test.sh  (in the root: installs the test packages, builds, runs every test)
#   5. in the pristine copy: apt-get install ./spherekit_<version>_amd64.deb (made by test.sh's
#      package test), then `spherekit run -o OUT` and `import spherekit` there
# Exit 0 when every step passed; the last lines are the table of steps and times.
set -euo pipefail

work=/var/tmp/spherekit-minimal-root
quick=0
ccache_dir=""
keep=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --quick) quick=1 ;;
    --ccache) ccache_dir="$(cd "$2" && pwd)"; shift ;;
    --keep) keep=1 ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    -*) echo "check_minimal_root: unknown option '$1'" >&2; exit 2 ;;
    *) work="$1" ;;
  esac
  shift
done
[[ "$(id -u)" == 0 ]] || { echo "check_minimal_root: needs root (debootstrap, chroot)" >&2; exit 2; }
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if ! command -v debootstrap >/dev/null 2>&1; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends debootstrap </dev/null
fi
# The host's mirror (deb822 .sources or a classic sources.list line).
mirror="$(sed -n 's/^URIs: *\([^ ]*\).*/\1/p' /etc/apt/sources.list.d/*.sources 2>/dev/null | grep -v security | head -1 || true)"
[[ -n "$mirror" ]] || mirror="$(awk '$1 == "deb" && $2 !~ /security/ {print $2; exit}' /etc/apt/sources.list 2>/dev/null || true)"
mirror="${mirror:-http://deb.debian.org/debian}"

root="$work/root"           # runs the two commands
pristine="$work/pristine"   # stays minimal: installs the .deb
mounted=()
cleanup() {
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do umount -l "${mounted[$i]}" 2>/dev/null || true; done
  if [[ "$keep" == 0 ]]; then rm -rf "$work"; fi
}
trap cleanup EXIT
mount_into() {  # mount_into ROOT: what chroot needs (processes, devices, shared memory for Chromium)
  local r="$1" d
  for d in proc sys dev; do
    mkdir -p "$r/$d"
    mount --rbind "/$d" "$r/$d"  # recursive: /dev/pts and /dev/shm (Chromium) too
    mount --make-rslave "$r/$d"
    mounted+=("$r/$d")
  done
  cp /etc/resolv.conf "$r/etc/resolv.conf"
}

steps=()
record() { steps+=("$(printf '%-58s %8s  %s' "$1" "$2" "$3")"); }
timed() {  # timed LABEL COMMAND...: runs it, records its wall time and verdict
  local label="$1" start status=0
  shift
  start=$(date +%s)
  echo "=== check_minimal_root: $label" >&2
  "$@" || status=$?
  local seconds=$(($(date +%s) - start))
  record "$label" "$((seconds / 60))m$(printf '%02d' $((seconds % 60)))s" "$([[ $status == 0 ]] && echo ok || echo "FAILED (exit $status)")"
  return "$status"
}
summary() {
  echo
  echo "check_minimal_root: Debian 12 minbase from $mirror"
  printf '%s\n' "${steps[@]}"
}

rm -rf "$work"
mkdir -p "$work"
timed "1. debootstrap --variant=minbase bookworm" \
  debootstrap --variant=minbase bookworm "$root" "$mirror" >"$work/debootstrap.log" 2>&1 \
  || { tail -20 "$work/debootstrap.log"; summary; exit 1; }
# The host's suites (updates, security) as apt sources of both roots, then the pristine copy.
rm -f "$root/etc/apt/sources.list"
cp /etc/apt/sources.list.d/*.sources "$root/etc/apt/sources.list.d/" 2>/dev/null \
  || echo "deb $mirror bookworm main" >"$root/etc/apt/sources.list"
# Local certificate authorities the host trusts (a proxy's, e.g.): without them npm's https
# requests fail in the roots on such networks (SELF_SIGNED_CERT_IN_CHAIN). The ca-certificates
# package, which install_deps.sh installs, takes them in.
if compgen -G "/usr/local/share/ca-certificates/*.crt" >/dev/null; then
  mkdir -p "$root/usr/local/share/ca-certificates"
  cp /usr/local/share/ca-certificates/*.crt "$root/usr/local/share/ca-certificates/"
fi
cp -a "$root" "$pristine"

timed "2. fresh clone of $(git -C "$repo" rev-parse --short HEAD) into the root" \
  git clone -q --no-hardlinks "$repo" "$root/root/spherekit" || { summary; exit 1; }

mount_into "$root"
env_vars=(HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8)
if [[ -n "$ccache_dir" ]]; then
  mkdir -p "$root/var/cache/spherekit-ccache"
  mount --bind "$ccache_dir" "$root/var/cache/spherekit-ccache"
  mounted+=("$root/var/cache/spherekit-ccache")
  chroot "$root" env DEBIAN_FRONTEND=noninteractive bash -c \
    'apt-get update -qq && apt-get install -y -qq --no-install-recommends ccache' </dev/null >/dev/null
  env_vars+=(CCACHE_DIR=/var/cache/spherekit-ccache CCACHE_BASEDIR=/root CMAKE_CXX_COMPILER_LAUNCHER=ccache
             CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime)
fi
in_root() { chroot "$root" env "${env_vars[@]}" bash -c "cd /root/spherekit && $1" </dev/null; }

status=0
timed "3. bash scripts/run.sh" in_root "bash scripts/run.sh >/root/run.log 2>&1" \
  || { tail -30 "$root/root/run.log"; status=1; }
grep -E "^\| |PSNR129|spherekit-out" "$root/root/run.log" | tail -12 || true
if [[ -f "$root/root/spherekit/spherekit-out/site/lib/three-viewer.js" ]]; then
  record "   results page has its 3-D viewer (site/lib/three-viewer.js)" "" ok
else
  record "   results page has its 3-D viewer (site/lib/three-viewer.js)" "" FAILED
  grep -i "warning" "$root/root/run.log" | tail -3 || true
  status=1
fi

test_env=""
if [[ "$quick" == 1 ]]; then test_env="SPHEREKIT_SKIP_SANITIZE=1 "; fi
timed "4. ${test_env}bash scripts/test.sh" in_root "${test_env}bash scripts/test.sh >/root/test.log 2>&1" || status=1
grep -E "tests passed|skipped|no test skipped|pytest|passed in|failed" "$root/root/test.log" | tail -12 || true

deb="$(ls "$root"/root/spherekit/build/tests/install-deb/pkg/spherekit_*_amd64.deb 2>/dev/null | head -1 || true)"
if [[ -z "$deb" ]]; then
  record "5. apt-get install ./spherekit_*.deb (pristine root)" "" "FAILED (test.sh made no package)"
  summary
  exit 1
fi
cp "$deb" "$pristine/root/"
mount_into "$pristine"
in_pristine() { chroot "$pristine" env "${env_vars[@]}" bash -c "cd /root && $1" </dev/null; }
timed "5. apt-get install ./$(basename "$deb") (pristine root)" in_pristine \
  "apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends ./$(basename "$deb") >/root/apt.log 2>&1" \
  || { tail -20 "$pristine/root/apt.log"; status=1; }
timed "   spherekit run -o out (installed package)" in_pristine "spherekit run -o /root/out -q >/root/pkg-run.log 2>&1" \
  || { tail -20 "$pristine/root/pkg-run.log"; status=1; }
timed "   python3 -c 'import spherekit' (installed package)" in_pristine \
  "python3 -c 'import spherekit; m = spherekit.read_mesh(\"/root/out/input/sample_a.obj\"); print(spherekit.__version__, spherekit.param(m, effort=0).flipped_faces)'" \
  || status=1
summary
exit "$status"
