#!/usr/bin/env bash
# `avs view` acceptance check (issue 17): installs the Foxglove client packages (pinned by
# js/package-lock.json) into the build tree, starts view_test_publisher and `avs view` on DDS
# domain DOMAIN, with tests/view/tf_graph.yaml (tf_publisher) launched by `avs launch`, and
# runs CHECK against the server: client (check_view.mjs, the Foxglove client), component (the
# same check against the `view` component inside tests/view/view_graph.yaml instead of `avs
# view`), bag (a bag recorded from the publisher, which then stops, played by `avs bag play
# --view`; check_bag_view.mjs), page (check_page.mjs, the page in headless Chromium; its
# screenshot is WORK_DIR/view_page.png) or demo (the page during `avs demo --view`, the
# lockstep closed loop, without the publisher; WORK_DIR/demo_page.png).
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
bash "$1/cmake/npm_ci.sh" "$src" "$work" view_client.mjs check_view.mjs check_bag_view.mjs check_page.mjs
cd "$work"
# Logs of an earlier run must not be read for this run's address: the background jobs below
# truncate them only once they start.
rm -f publisher.log record.log info.log graph.log view.log
: > graph.log
: > view.log
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
}
trap cleanup EXIT
if [ "$check" != demo ]; then
  "$publisher" "$domain" > publisher.log 2>&1 &
  pids+=($!)
fi
if [ "$check" = demo ]; then
  # Long enough for the page under any load: the check ends it once the page has passed.
  rm -rf demo_run
  "$avs" demo --view --view-port 0 --seconds 30 --out demo_run > view.log 2>&1 &
  pids+=($!)
  view_log=view.log
elif [ "$check" = bag ]; then
  rm -f view_check.mcap
  AVS_DOMAIN_ID="$domain" "$avs" bag record /object/pose /depth/image -o view_check.mcap \
    --duration 4 > record.log 2>&1
  kill "${pids[0]}"  # the publisher: from now on only the player writes these topics
  wait "${pids[0]}" 2>/dev/null || true
  "$avs" bag info view_check.mcap > info.log
  # At least 20 poses and 3 images recorded, or the check below could not pass.
  poses=$(awk '$1 == "/object/pose" {for (i = 2; i <= NF; i++) if ($i ~ /^[0-9]+$/) {print $i; exit}}' info.log)
  images=$(awk '$1 == "/depth/image" {for (i = 2; i <= NF; i++) if ($i ~ /^[0-9]+$/) {print $i; exit}}' info.log)
  if [ "${poses:-0}" -lt 20 ] || [ "${images:-0}" -lt 3 ]; then
    echo "FAILED: the recording has ${poses:-0} poses and ${images:-0} images (want 20 and 3)" >&2
    cat record.log info.log >&2
    exit 1
  fi
  "$avs" bag play view_check.mcap --loop --view --view-port 0 --domain "$domain" > view.log 2>&1 &
  pids+=($!)
  view_log=view.log
elif [ "$check" = component ]; then
  AVS_DOMAIN_ID="$domain" "$avs" launch "$1/tests/view/view_graph.yaml" > graph.log 2>&1 &
  pids+=($!)
  view_log=graph.log  # the component logs its address there
else
  AVS_DOMAIN_ID="$domain" "$avs" launch "$1/tests/view/tf_graph.yaml" > graph.log 2>&1 &
  pids+=($!)
  "$avs" view --port 0 --domain "$domain" > view.log 2>&1 &
  pids+=($!)
  view_log=view.log
fi
port=""
for _ in $(seq 1 300); do
  port=$(sed -n 's|.*ws://127.0.0.1:\([0-9]*\).*|\1|p' "$view_log" | head -1)
  [ -n "$port" ] && break
  sleep 0.1
done
if [ -z "$port" ]; then
  echo "FAILED: avs view did not print its address" >&2
  cat "$view_log" >&2
  exit 1
fi
status=0
if [ "$check" = page ] || [ "$check" = demo ]; then
  if [ ! -x "${AVS_CHROMIUM:-/usr/bin/chromium}" ]; then
    echo "FAILED: no chromium (bash tools/run.sh test installs Debian's chromium)" >&2
    exit 1
  fi
  if [ "$check" = page ]; then
    node check_page.mjs "http://127.0.0.1:$port/" "$work/view_page.png" || status=$?
  else
    # The address the demo printed, with its page options (?object=ken).
    url=$(sed -n 's|.*live view at \(http://[^ ]*\).*|\1|p' view.log | head -1)
    AVS_PAGE_EXPECT=demo node check_page.mjs "$url" "$work/demo_page.png" 300 || status=$?
  fi
elif [ "$check" = bag ]; then
  node check_bag_view.mjs "ws://127.0.0.1:$port" || status=$?
else
  node check_view.mjs "ws://127.0.0.1:$port" "$publisher" "$domain" || status=$?
fi
if [ "$view_log" = view.log ]; then
  echo "--- avs view log:"
  cat view.log
fi
echo "--- graph log:"
cat graph.log
exit $status
