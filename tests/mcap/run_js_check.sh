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
bash "$1/cmake/npm_ci.sh" "$src" "$work" check_mcap.mjs
cd "$work"
"$fixture" "$work"
node check_mcap.mjs expected.json avs_none.mcap avs_lz4.mcap avs_zstd.mcap
