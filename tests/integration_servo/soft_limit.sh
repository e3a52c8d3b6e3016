#!/usr/bin/env bash
# Issue 20 1.4: the soft limits' velocity envelope. Before it, 1 N m held for 0.4 s took pan to
# 4.18 rad against the 3.0 rad limit and a saturated command took pan to 7.0 rad and tilt to
# -3.84 rad against -1.4. The plant's truth (/sim/head_state) must never pass a limit by more
# than 1 mrad, and the axis must still get near it (the envelope does not stop it early).
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration_servo/lib.sh"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
tolerance_rad=0.001
# extreme FILE COLUMN max|min: the largest / smallest value of a CSV column.
extreme() {
  awk -F, -v c="$(column "$1" "$2")" -v m="$3" \
    'NR==2 {x=$c} NR>1 {if ((m=="max" && $c>x) || (m=="min" && $c<x)) x=$c} END {print x}' "$1"
}
run_head "$out/held" duration_s:=1.0 "torque_nm:=[1.0, 0.0]" step_at_s:=0.05 step_until_s:=0.45
pan_max=$(extreme "$out/held/recorder_sim.csv" pan_q_rad max)
echo "held 1 N m for 0.4 s: pan max $pan_max rad (limit 3.0)"
awk -v x="$pan_max" -v t="$tolerance_rad" 'BEGIN {exit !(x <= 3.0 + t)}' || fail "pan passed 3.0 rad: $pan_max"
awk -v x="$pan_max" 'BEGIN {exit !(x > 2.9)}' || fail "pan stopped far before the limit: $pan_max"

run_head "$out/sat" duration_s:=1.0 "torque_nm:=[100.0, -100.0]" step_at_s:=0.05 step_until_s:=10
pan_max=$(extreme "$out/sat/recorder_sim.csv" pan_q_rad max)
tilt_min=$(extreme "$out/sat/recorder_sim.csv" tilt_q_rad min)
echo "saturated: pan max $pan_max rad (limit 3.0), tilt min $tilt_min rad (limit -1.4)"
awk -v x="$pan_max" -v t="$tolerance_rad" 'BEGIN {exit !(x <= 3.0 + t)}' || fail "pan passed 3.0 rad: $pan_max"
awk -v x="$tilt_min" -v t="$tolerance_rad" 'BEGIN {exit !(x >= -1.4 - t)}' || fail "tilt passed -1.4 rad: $tilt_min"
awk -v x="$tilt_min" 'BEGIN {exit !(x < -1.35)}' || fail "tilt stopped far before the limit: $tilt_min"
echo PASS
