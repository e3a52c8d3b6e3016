#!/usr/bin/env bash
# Issue 20 section 5: each container of the closed loop (closed_loop_processes.yaml, one
# process per stage, respawn: always) killed with SIGKILL in turn by `avs bench faults`.
# What must hold whatever the machine's load: every container comes back and its output with
# it; with tracking dead the drive reaches zero torque and never commands torque from a
# command older than its timeout (its own cycle stamps); with the drive dead the amplifiers'
# watchdog takes the torque off; tracking goes on commanding while matching is gone; every
# file the recorder wrote (the killed one too) is readable. The times are printed, not judged.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration/lib.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$avs" bench faults --json --warm-up=3 --settle=2 --dir="$work" > "$work/result.json" \
  2> "$work/bench.log" || { cat "$work/bench.log"; cat "$work/launch.log" 2>/dev/null | tail -50; fail "avs bench faults failed"; }
cat "$work/bench.log"
python3 - "$work/result.json" <<'PY' || { tail -80 "$work/launch.log"; fail "see above"; }
import json, sys
r = json.load(open(sys.argv[1]))
print(json.dumps(r, indent=1, sort_keys=True))
bad = []
def need(cond, what):
    if not cond: bad.append(what)
need(r["containers_killed"] == 6, "6 containers killed")
need(r["containers_recovered"] == 6, "every container and its output back")
for c in ["recorder", "matcher", "vision", "control", "drive", "world"]:
    need(r[f"kill.{c}.respawned"] == 1, f"{c} restarted")
    need(r[f"kill.{c}.recovered"] == 1, f"{c}'s output back")
need(r["kill.control.zero_torque_after_ms"] is not None, "zero torque after tracking died")
need(r["kill.control.stale_torque_cycles"] == 0, "no torque from a stale command")
need(r["kill.drive.amplifier_zero_torque_after_ms"] is not None,
     "the amplifiers' watchdog took the torque off after the drive died")
# The longest gap in torque commands over the matcher's absence is shorter than the absence:
# commands came while it was gone.
need(r["kill.matcher.servo_gap_s"] < r["kill.matcher.gone_s"],
     "tracking went on commanding while matching was gone")
need(r["recordings"] >= 2, "the killed recorder's file and its successor's")
need(r["recordings_readable"] == r["recordings"], "every recording readable")
need(r["recorded_messages"] > 0, "messages recorded")
if bad:
    print("FAIL:", "; ".join(bad)); sys.exit(1)
PY
echo PASS
