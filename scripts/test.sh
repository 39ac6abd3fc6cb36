#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (ctest, 2 jobs). CI runs this.
#   bash scripts/test.sh
#   bash scripts/test.sh -L cli      (extra arguments go to ctest)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

bash "$root/scripts/install_deps.sh"
bash "$root/scripts/build.sh"

log="$(mktemp)"
trap 'rm -f "$log"' EXIT
status=0
ctest --test-dir "$root/build" --output-on-failure -j2 "$@" 2>&1 | tee "$log" || status=$?
# Repeat ctest's verdict as the last line, so it is the first thing one sees in a long log.
summary="$(grep -E '^[0-9]+% tests passed' "$log" | tail -1 || true)"
echo "${summary:-ctest printed no summary}"
exit "$status"
