# Sourced by setup_npm_tools.sh and setup_viewer.sh: pinned npm packages installed into a folder
# of their own, outside the repository.
#   npm_pinned_install TAG PACKAGE_NAME DIR SPEC...
# takes DIR's lock (fd 9, held until the caller exits, so concurrent runs wait for each other),
# installs every SPEC (name@version) not present in that version, and checks again. On failure
# it prints "TAG: ..." and exits 3 (the callers' "unavailable" code).
#   npm_installed_version DIR NAME   -> the installed version, or nothing

npm_installed_version() {
  local pj="$1/node_modules/$2/package.json"
  [[ -f "$pj" ]] && node -p "require(process.argv[1]).version" "$pj" 2>/dev/null || true
}

npm_missing() {  # npm_missing DIR SPEC... -> the specs not installed in their version
  local dir="$1" spec name version out=()
  shift
  for spec in "$@"; do
    name="${spec%@*}"; version="${spec##*@}"
    [[ "$(npm_installed_version "$dir" "$name")" == "$version" ]] || out+=("$spec")
  done
  echo "${out[@]:-}"
}

npm_pinned_install() {
  local tag="$1" package_name="$2" dir="$3" todo
  shift 3
  mkdir -p "$dir"
  exec 9>"$dir/.lock"
  flock 9
  todo="$(npm_missing "$dir" "$@")"
  [[ -z "$todo" ]] && return 0
  echo "$tag: installing $todo into $dir" >&2
  [[ -f "$dir/package.json" ]] || echo "{ \"name\": \"$package_name\", \"version\": \"0.0.0\", \"private\": true }" >"$dir/package.json"
  # shellcheck disable=SC2086  # $todo is a list of package specs
  if ! (cd "$dir" && npm install --no-audit --no-fund --loglevel=error $todo >&2); then
    echo "$tag: npm install failed (is the npm registry reachable?)" >&2
    exit 3
  fi
  todo="$(npm_missing "$dir" "$@")"
  if [[ -n "$todo" ]]; then
    echo "$tag: still missing after npm install: $todo" >&2
    exit 3
  fi
}
