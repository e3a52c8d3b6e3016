#!/usr/bin/env bash
# Installs the npm packages of a JS folder, pinned by its package-lock.json, into a folder of
# the build tree (once per lock file), after copying the named files there. Used by the
# checks that run official JS libraries against avs (tests/mcap, tests/view) and by the build
# of the `avs view` page (libs/view/page).
# usage: npm_ci.sh SOURCE_JS_DIR WORK_DIR FILE...
set -euo pipefail
src="$1"
work="$2"
shift 2
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  # tools/run.sh test installs them; a skip here would hide a missing step.
  echo "FAILED: node/npm not installed (bash tools/run.sh test installs nodejs and npm)" >&2
  exit 1
fi
mkdir -p "$work"
cp "$src/package.json" "$src/package-lock.json" "$work/"
for f in "$@"; do cp "$src/$f" "$work/"; done  # flat: src/main.js -> WORK/main.js
cd "$work"
if ! cmp -s package-lock.json node_modules/.avs-installed-lock 2>/dev/null; then
  npm ci --no-audit --no-fund --loglevel=error
  cp package-lock.json node_modules/.avs-installed-lock
fi
