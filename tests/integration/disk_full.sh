#!/usr/bin/env bash
# Issue 20 section 5: the disk fills up while recording (a 3 MB tmpfs, in a mount namespace of
# this test's own). The recorder stops with a clear message, its file is readable up to its
# last complete chunk and what it says it wrote is what the file holds, and nothing else in
# the graph stops: once with the bag_recorder inside a lockstep graph, once with
# `avs bag record` in another process.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration/lib.sh"
if [ -z "${AVS_DISK_FULL_NS:-}" ]; then
  # A private mount namespace, so the tmpfs is seen by this test only and vanishes with it.
  if ! unshare -m --propagation private true 2>/dev/null; then
    echo "SKIP: needs root (unshare -m, mount -t tmpfs) to make a small disk; NOT tested here"
    exit 77
  fi
  AVS_DISK_FULL_NS=1 exec unshare -m --propagation private bash "$0" "$@"
fi
work=$(mktemp -d)
small=$work/small
mkdir -p "$small"
mount -t tmpfs -o size=3m tmpfs "$small"
trap 'kill $(jobs -p) 2>/dev/null || true; umount "$small" 2>/dev/null || true; rm -rf "$work"' EXIT

in_file() {  # messages in a bag, read as `avs bag info` reads it (a scan when it has no summary)
  "$avs" bag info "$1" | awk '/^Messages:/ {print $2}'
}

echo "== bag_recorder inside a lockstep graph"
"$avs" launch "$src/tests/integration/data/disk_full.yaml" file:="$small/graph.mcap" \
  > "$work/graph.log" 2>&1 || { cat "$work/graph.log"; fail "the graph failed: a full disk stopped it"; }
cat "$work/graph.log" | grep -v '^\s*$' | tail -6
grep -q "No space left on device" "$work/graph.log" || fail "no word of the full disk"
grep -q "recording STOPPED" "$work/graph.log" || fail "the recorder did not say it stopped"
grep -q "299 frames, 149 pairs, 149 depth maps" "$work/graph.log" ||
  fail "decode did not go on to the end of the run"
said=$(sed -n 's/.*: \([0-9]*\) message(s) in the file, [0-9]* NOT written.*/\1/p' "$work/graph.log")
[ -n "$said" ] || fail "the recorder did not say how many messages the file holds"
have=$(in_file "$small/graph.mcap")
echo "recorder says $said in the file, avs bag info reads $have"
[ "$have" -gt 0 ] || fail "nothing readable in the file"
[ "$have" -eq "$said" ] || fail "the recorder says $said messages are in the file, it has $have"

echo "== avs bag record in another process"
rm -f "$small/graph.mcap"
"$avs" bag record /camera/pattern -o "$small/record.mcap" > "$work/record.log" 2>&1 &
rec=$!
sleep 1
"$avs" launch "$src/tests/integration/data/disk_full_source.yaml" > "$work/source.log" 2>&1 ||
  { cat "$work/source.log"; fail "the source graph failed"; }
grep -q "299 frames\|[0-9]* frames, " "$work/source.log" || fail "the source graph did not run"
for _ in $(seq 50); do kill -0 $rec 2>/dev/null || break; sleep 0.2; done
kill -INT $rec 2>/dev/null || true
status=0; wait $rec || status=$?
cat "$work/record.log"
[ "$status" -ne 0 ] || fail "avs bag record exited 0 although its disk filled up"
grep -q "No space left on device" "$work/record.log" || fail "no word of the full disk"
line=$(grep '^total: ' "$work/record.log") || fail "no end-of-recording report"
received=$(echo "$line" | sed 's/total: \([0-9]*\) received, \([0-9]*\) written, \([0-9]*\) lost.*/\1/')
written=$(echo "$line" | sed 's/total: \([0-9]*\) received, \([0-9]*\) written, \([0-9]*\) lost.*/\2/')
lost=$(echo "$line" | sed 's/total: \([0-9]*\) received, \([0-9]*\) written, \([0-9]*\) lost.*/\3/')
have=$(in_file "$small/record.mcap")
echo "received $received, written $written, lost $lost; avs bag info reads $have"
[ "$have" -gt 0 ] || fail "nothing readable in the file"
[ "$written" -eq "$have" ] || fail "the report says $written written, the file holds $have"
[ $((written + lost)) -eq "$received" ] || fail "received $received != written $written + lost $lost"
grep -q "not written (the file failed)" "$work/record.log" || fail "the loss has no cause"
echo "OK"
