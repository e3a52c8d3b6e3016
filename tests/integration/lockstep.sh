#!/usr/bin/env bash
# A graph in simulated time, lockstep: the result depends only on the graph, never on the
# machine's load. Run it twice, once with both cores busy, and compare.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration/lib.sh"
out=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$out"' EXIT
graph="$src/tests/integration/data/lockstep.yaml"

mkdir -p "$out/a" "$out/b"
"$avs" launch "$graph" report_dir:="$out/a" 2>/dev/null || fail "first run failed"
for i in 1 2; do (while :; do :; done) & done   # load both cores
"$avs" launch "$graph" report_dir:="$out/b" 2>/dev/null || fail "second run failed"
kill $(jobs -p)

cat "$out/a/listener.yaml"
# 1 kHz for 2 s of sim time: ticks at 1 ms ... 1999 ms, the 2000th falls on the end.
[ "$(value "$out/a/listener.yaml" received)" -eq 1999 ] || fail "expected 1999 samples"
diff "$out/a/listener.yaml" "$out/b/listener.yaml" || fail "runs differ"
echo PASS
