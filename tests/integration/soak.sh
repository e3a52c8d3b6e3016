#!/usr/bin/env bash
# Issue 20 section 5, `avs bench soak` in short: the closed loop in six processes for 45 s,
# every container sampled each second (resident memory, descriptors), none restarted, poses
# flowing, the plot made. The growth figures of a long run are in docs/reliability.md; a run
# this short judges none of them.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration/lib.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$avs" bench soak --json --minutes=0.75 --warm-up=20 --dir="$work" > "$work/result.json" \
  2> "$work/bench.log" || { cat "$work/bench.log"; tail -50 "$work/launch.log" 2>/dev/null; fail "avs bench soak failed"; }
python3 - "$work/result.json" <<'PY' || { tail -50 "$work/launch.log"; fail "see above"; }
import json, sys
r = json.load(open(sys.argv[1]))
print(json.dumps(r, indent=1, sort_keys=True))
bad = []
for c in ["world", "vision", "control", "drive", "matcher", "recorder"]:
    if not r[f"container.{c}.samples"] >= 15: bad.append(f"{c} sampled after the warm-up")
    if r[f"container.{c}.rss_kib_per_min"] is None: bad.append(f"{c}: a memory slope")
    if r[f"container.{c}.rss_peak_kib_growth_between_halves"] is None: bad.append(f"{c}: a peak growth")
    if r[f"container.{c}.fds_end"] is None or r[f"container.{c}.fds_end"] <= 0: bad.append(f"{c}: descriptors read")
if r["container_restarts"] != 0: bad.append("no container restarted")
if not r["pose_rate_hz"] > 0: bad.append("poses after the warm-up")
if not r["loss_counters_seen"] > 0: bad.append("loss counters read from /diagnostics")
if bad:
    print("FAIL:", "; ".join(bad)); sys.exit(1)
PY
[ -s "$work/soak.png" ] || fail "no soak.png"
echo PASS
