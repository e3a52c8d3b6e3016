#!/usr/bin/env bash
# Issue 20 section 2: `avs launch` killed with SIGKILL (it cannot stop anything itself) must not
# leave its containers running. Each container asks for SIGTERM when its launcher goes
# (runtime/process.hpp); this checks that both containers of the talker graph are gone within
# 5 s of the kill, and that a second launch of the same graph then runs normally.
set -uo pipefail
avs=$1; src=$2
. "$src/tests/integration/lib.sh"
out=$(mktemp -d); trap 'kill -9 $(jobs -p) 2>/dev/null; rm -rf "$out"' EXIT
graph="$src/tests/support/graphs/talker_listener.yaml"

"$avs" launch "$graph" rate_hz:=100 2> "$out/log" &
launcher=$!
children=""
for _ in $(seq 100); do  # up to 10 s for both containers to start
  children=$(pgrep -P "$launcher" | tr '\n' ' ')
  [ "$(wc -w <<<"$children")" -eq 2 ] && break
  sleep 0.1
done
[ "$(wc -w <<<"$children")" -eq 2 ] || { cat "$out/log"; fail "expected 2 containers, got '$children'"; }
sleep 1  # running and publishing
kill -9 "$launcher"
wait "$launcher" 2>/dev/null
alive=""
for _ in $(seq 50); do
  alive=""
  for pid in $children; do kill -0 "$pid" 2>/dev/null && alive+="$pid "; done
  [ -z "$alive" ] && break
  sleep 0.1
done
[ -z "$alive" ] || { kill -9 $alive; fail "containers still running 5 s after their launcher was killed: $alive"; }
echo "ok: both containers ($children) ended after the launcher was killed"

timeout 30 "$avs" launch "$graph" duration_s:=1 rate_hz:=100 report_dir:="$out" 2> "$out/log2" \
  || { cat "$out/log2"; fail "the second launch failed"; }
received=$(value "$out/remote_listener.yaml" received)
((${received:-0} > 10)) || fail "the second launch's remote listener received ${received:-nothing}"
echo PASS
