#!/usr/bin/env bash
# `avs view` acceptance check (issue 17): installs the Foxglove client packages (pinned by
# js/package-lock.json) into the build tree, starts view_test_publisher and `avs view` on DDS
# domain DOMAIN, with tests/view/tf_graph.yaml (tf_publisher) launched by `avs launch`, and
# runs CHECK against the server: client (check_view.mjs, the Foxglove client) or page
# (check_page.mjs, the page in headless Chromium; its screenshot is WORK_DIR/view_page.png).
# usage: run_view_check.sh SOURCE_DIR WORK_DIR AVS_BINARY PUBLISHER_BINARY CHECK
# (DOMAIN: leased by tests/support/test_domain.sh)
set -euo pipefail
src="$1/tests/view/js"
work="$2"
avs="$3"
publisher="$4"
. "$(dirname "${BASH_SOURCE[0]}")/../support/test_domain.sh"
domain="$AVS_DOMAIN_ID"
check="$5"
bash "$1/cmake/npm_ci.sh" "$src" "$work" check_view.mjs check_page.mjs
cd "$work"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
}
trap cleanup EXIT
"$publisher" "$domain" > publisher.log 2>&1 &
pids+=($!)
AVS_DOMAIN_ID="$domain" "$avs" launch "$1/tests/view/tf_graph.yaml" > graph.log 2>&1 &
pids+=($!)
"$avs" view --port 0 --domain "$domain" > view.log 2>&1 &
pids+=($!)
port=""
for _ in $(seq 1 300); do
  port=$(sed -n 's|.*ws://127.0.0.1:\([0-9]*\).*|\1|p' view.log | head -1)
  [ -n "$port" ] && break
  sleep 0.1
done
if [ -z "$port" ]; then
  echo "FAILED: avs view did not print its address" >&2
  cat view.log >&2
  exit 1
fi
status=0
if [ "$check" = page ]; then
  if [ ! -x "${AVS_CHROMIUM:-/usr/bin/chromium}" ]; then
    echo "FAILED: no chromium (bash tools/run.sh test installs Debian's chromium)" >&2
    exit 1
  fi
  node check_page.mjs "http://127.0.0.1:$port/" "$work/view_page.png" || status=$?
else
  node check_view.mjs "ws://127.0.0.1:$port" "$publisher" "$domain" || status=$?
fi
echo "--- avs view log:"
cat view.log
echo "--- graph log:"
cat graph.log
exit $status
