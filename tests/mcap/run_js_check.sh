#!/usr/bin/env bash
# Independent MCAP reader check (issue 7): installs the official MCAP TypeScript packages
# (pinned by js/package-lock.json) into the build tree, writes files with avs::mcap and checks
# that @mcap/core reads them (indexed and streamed, CRCs validated) and that every message
# decodes, with the schemas stored in the file, to the values that were written.
# usage: run_js_check.sh SOURCE_DIR WORK_DIR FIXTURE_BINARY
set -euo pipefail
src="$1/tests/mcap/js"
work="$2"
fixture="$3"
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  # The test command installs them (tools/run.sh); a skip here would hide a missing step.
  echo "FAILED: node/npm not installed (bash tools/run.sh test installs nodejs and npm)" >&2
  exit 1
fi
mkdir -p "$work"
cp "$src/package.json" "$src/package-lock.json" "$src/check_mcap.mjs" "$work/"
cd "$work"
if ! cmp -s package-lock.json node_modules/.avs-installed-lock 2>/dev/null; then
  npm ci --no-audit --no-fund --loglevel=error
  cp package-lock.json node_modules/.avs-installed-lock
fi
"$fixture" "$work"
node check_mcap.mjs expected.json avs_none.mcap avs_lz4.mcap avs_zstd.mcap
