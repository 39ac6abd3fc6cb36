#!/usr/bin/env bash
# Builds the libFuzzer harnesses (tools/fuzz) with clang into build-fuzz/ and runs each for a
# fixed time, one after the other.
#
#   bash scripts/fuzz.sh [SECONDS_PER_HARNESS] [HARNESS...]     (default 600 s, all harnesses)
#   bash scripts/fuzz.sh 60 ply obj                              (one minute each for two)
#
# Harnesses: obj ply off stl gltf glb compressed landmarks sphere_points targets sphere_map attributes
# collection.
# The seeds (tools/fuzz/corpus/NAME) are copied into build-fuzz/corpus/NAME, which keeps
# growing across runs; the source tree is never written. A crash, leak, sanitizer report,
# timeout or broken reader contract stops that harness, leaves the input in
# build-fuzz/artifacts/NAME/ and makes the script exit 1 after the others have run. Turn each
# finding into a case of tests/data/bad/ (see its README.md) once fixed.
# Runs at nice 10 with one job: the machines are shared. Logs: build-fuzz/logs/NAME.log.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

seconds="${1:-600}"
[[ "$seconds" =~ ^[0-9]+$ ]] || { echo "fuzz.sh: SECONDS must be a whole number, got '$seconds'" >&2; exit 2; }
shift || true
all=(obj ply off stl gltf glb compressed landmarks sphere_points targets sphere_map attributes collection)
harnesses=("$@")
[ ${#harnesses[@]} -gt 0 ] || harnesses=("${all[@]}")
for h in "${harnesses[@]}"; do
  [[ " ${all[*]} " == *" $h "* ]] || { echo "fuzz.sh: unknown harness '$h' (${all[*]})" >&2; exit 2; }
done

command -v clang++ >/dev/null || { echo "fuzz.sh: needs clang++ (apt-get install clang)" >&2; exit 2; }
build=build-fuzz
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DSPHEREKIT_BUILD_FUZZERS=ON -DSPHEREKIT_BUILD_TESTS=OFF -DSPHEREKIT_BUILD_TOOLS=OFF >/dev/null
# Only the harnesses to run: the collection one alone compiles the command line's CLI11 code.
nice -n 10 cmake --build "$build" -j 1 --target "${harnesses[@]/#/fuzz_}"

# Which dictionary helps which harness (the feature files have no keywords).
dict_for() {
  case "$1" in
    obj | sphere_map) echo tools/fuzz/dict/obj.dict ;;
    ply) echo tools/fuzz/dict/ply.dict ;;
    attributes) echo tools/fuzz/dict/attributes.dict ;;
    collection) echo tools/fuzz/dict/collection.dict ;;
    off) echo tools/fuzz/dict/off.dict ;;
    stl) echo tools/fuzz/dict/stl.dict ;;
    gltf | glb) echo tools/fuzz/dict/gltf.dict ;;
  esac
}

mkdir -p "$build/logs"
failed=()
printf '%-14s %8s %12s %10s  %s\n' harness seconds executions exec/s result
for h in "${harnesses[@]}"; do
  corpus="$build/corpus/$h" artifacts="$build/artifacts/$h"
  mkdir -p "$corpus" "$artifacts"
  cp -n tools/fuzz/corpus/"$h"/* "$corpus"/ 2>/dev/null || true
  args=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1
        -artifact_prefix="$artifacts/")
  dict="$(dict_for "$h")"
  [ -z "$dict" ] || args+=(-dict="$dict")
  log="$build/logs/$h.log"
  result=ok
  start=$SECONDS
  nice -n 10 "$build/tools/fuzz/fuzz_$h" "${args[@]}" "$corpus" >"$log" 2>&1 || result=FINDING
  elapsed=$((SECONDS - start))  # less than asked when a finding stops the harness
  runs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  rate="$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)"
  printf '%-14s %8s %12s %10s  %s\n' "$h" "$elapsed" "${runs:-?}" "${rate:-?}" "$result"
  if [ "$result" != ok ]; then
    failed+=("$h")
    grep -m1 -E "ERROR: |SUMMARY: |deadly signal" "$log" | sed 's/^/    /' || true
    ls "$artifacts" | sed 's/^/    artifact: /' || true
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz.sh: findings in ${failed[*]} (logs in $build/logs, inputs in $build/artifacts)" >&2
  exit 1
fi
echo "fuzz.sh: no findings"
