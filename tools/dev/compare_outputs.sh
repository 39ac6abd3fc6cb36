#!/usr/bin/env bash
# Runs every product command on the built-in samples with two `spherekit` programs and
# compares what they write, file by file, with cmp. JSON files are compared after removing
# what legitimately differs run to run (timings, memory, version strings). Both programs run
# in the same folder one after the other, so absolute paths inside the outputs are equal.
#
#   tools/dev/compare_outputs.sh OLD_SPHEREKIT NEW_SPHEREKIT [WORK_DIR] [--no-run]
#
# Sizes are small (effort 0, 33 x 33 images, few PSNR samples) so that it runs in a few
# minutes on a loaded machine; `run` (the main job, which has no size flags) runs unless
# --no-run. Exit 0 when everything matches, 1 otherwise (the differing files are listed).
set -uo pipefail
old=$(realpath "$1"); new=$(realpath "$2"); work=${3:-/tmp/spherekit-compare}
with_run=1
[[ "${4:-}" == "--no-run" || "${3:-}" == "--no-run" ]] && with_run=0
[[ "${3:-}" == "--no-run" ]] && work=/tmp/spherekit-compare
rm -rf "$work"; mkdir -p "$work"

jobs() {  # $1 = program; runs in ./out
  local sk=$1
  mkdir -p out/conv out/transfer && cd out || return 1
  "$sk" samples -o samples --members 3 --vertices 600 || return 1
  "$sk" param samples/sample_a.obj -o a.sphere.obj --report param.json --effort 0 -q || return 1
  "$sk" consistent -o col samples/sample_a.obj samples/sample_b.obj samples/sample_c.obj --effort 0 \
    --remesh-size 17 --report consistent.json -q || return 1
  "$sk" param samples/sample_b.obj -o b_constrained.sphere.obj --features samples/sample_b.lm.txt \
    --targets col/features.txt --dump-network network.obj --report param_constrained.json --effort 0 -q || return 1
  "$sk" convert samples/sample_a.obj a.sphere.obj -o conv/a.exr --size 33 --lods 2 --cage 2 --cage-tile 5 \
    --psnr-samples 4000 --remesh conv/a.gim.obj --report conv/a.json -q || return 1
  "$sk" convert --collection col -o assets --size 33 --lods 2 --cage 2 --cage-tile 5 --psnr-samples 4000 \
    --report assets.json -q || return 1
  "$sk" transfer col --from sample_a --to sample_b --what normals -o transfer/b_normals.obj --size 33 \
    --report transfer.json -q || return 1
  "$sk" morph col sample_a sample_b -o morph --frames 3 --size 17 -q || return 1
  "$sk" pca col -o pca --size 17 -q || return 1
  if (( with_run )); then "$sk" run -o run -q > run.stdout || return 1; fi
  cd ..
}

for side in old new; do
  sk=$old; [[ $side == new ]] && sk=$new
  echo "== $side: $sk"
  start=$SECONDS
  (cd "$work" && jobs "$sk") > "$work/$side.log" 2>&1 || { echo "$side failed, see $work/$side.log"; tail -5 "$work/$side.log"; exit 1; }
  mv "$work/out" "$work/$side"
  echo "   $((SECONDS - start)) s"
done

# The JSON without timings and versions, keys sorted: equal means equal results.
normalize() {
  python3 - "$1" <<'PY'
import json, sys
VOLATILE = {"times", "seconds", "wall_seconds", "cpu_seconds", "peak_rss_mb", "version", "library_version"}
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if k not in VOLATILE}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
print(json.dumps(strip(json.load(open(sys.argv[1]))), indent=1, sort_keys=True))
PY
}

# The page with the cells of every column headed "time s" or "seconds" blanked.
page_without_timings() {
  python3 - "$1" <<'PY'
import re, sys
html = open(sys.argv[1]).read()
def blank(table):
    heads = re.findall(r"<th>(.*?)</th>", table)
    timing = {i for i, h in enumerate(heads) if h in ("time s", "seconds")}
    def row(m):
        cells = re.findall(r"<td[^>]*>.*?</td>", m.group(0))
        return "<tr>" + "".join("<td>-</td>" if i in timing else c for i, c in enumerate(cells)) + "</tr>"
    return re.sub(r"<tr>(?:<td[^>]*>.*?</td>\s*)+</tr>", row, table, flags=re.S)
print(re.sub(r"<table.*?</table>", lambda m: blank(m.group(0)), html, flags=re.S))
PY
}

status=0; same=0
while IFS= read -r f; do
  a="$work/old/$f"; b="$work/new/$f"
  if [[ ! -e "$b" ]]; then echo "only in old: $f"; status=1; continue; fi
  case "$f" in
    *.json) if cmp -s <(normalize "$a" 2>/dev/null) <(normalize "$b" 2>/dev/null); then ((same++)); else echo "differs (JSON): $f"; status=1; fi ;;
    *.stdout|*.log) ;;  # timings
    # The results page: the cells of its tables' timing columns ("time s", "seconds") vary.
    */index.html) if cmp -s <(page_without_timings "$a") <(page_without_timings "$b"); then ((same++)); \
                  else echo "differs (page, timings aside): $f"; status=1; fi ;;
    *) if cmp -s "$a" "$b"; then ((same++)); else echo "differs: $f"; status=1; fi ;;
  esac
done < <(cd "$work/old" && find . -type f | sort)
while IFS= read -r f; do [[ -e "$work/old/$f" ]] || { echo "only in new: $f"; status=1; }; done < <(cd "$work/new" && find . -type f | sort)
echo "$same files identical"
exit $status
