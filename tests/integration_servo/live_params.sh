#!/usr/bin/env bash
# servo_drive's live parameters (issue 18 section 1): while the lockstep head graph runs,
# `avs param set drive soft_upper_rad '[0.2, 1.4]'` from another process; then the torque step
# starts (a live parameter of the test source, so the order is certain) and the pan axis, which
# the default 3.0 rad limit would let run on, stops at the new limit. A restart-only parameter
# and an inconsistent limit are refused with the reason, and nothing changes.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration_servo/lib.sh"
out=$(mktemp -d)
start_lockstep "$out/a" "$graph" report_dir:="$out/a" duration_s:=0 "torque_nm:=[0.5, 0]" \
  step_at_s:=1000000 step_until_s:=2000000
wait_for "running 4 component"
param() { "$avs" param "$@" >"$out/param.txt" 2>&1; }
param set drive soft_upper_rad '[0.2, 1.4]' || { cat "$out/param.txt" >&2; fail "set refused"; }
cat "$out/param.txt"
grep -q "soft_upper_rad = \[0.2, 1.4\] (was \[3, 1.4\])" "$out/param.txt" || fail "no change shown"
! param set drive max_torque_nm '[1, 1]' || fail "a restart-only parameter was changed"
grep -q "max_torque_nm is not dynamic" "$out/param.txt" || { cat "$out/param.txt"; fail "reason"; }
! param set drive soft_upper_rad '[-5, 1.4]' || fail "an upper limit below the lower one was taken"
grep -q "soft_lower_rad must be below soft_upper_rad" "$out/param.txt" ||
  { cat "$out/param.txt"; fail "no reason for the inconsistent limit"; }
! param set drive brake_gain_nm_s_per_rad '[-1, 0.05]' || fail "a negative brake gain was taken"
grep -q "in \[0, 1000\]" "$out/param.txt" || { cat "$out/param.txt"; fail "no range in the refusal"; }
param get drive soft_upper_rad && grep -qx "\[0.2, 1.4\]" "$out/param.txt" ||
  { cat "$out/param.txt"; fail "the refused change altered the value in force"; }
param set source step_at_s 0 || { cat "$out/param.txt" >&2; fail "could not start the step"; }
# 500 joint states after the step started (0.5 s of sim time): pan would be far past 0.2 rad.
"$avs" topic echo /head/joint_states -n 500 --wait 60 >/dev/null ||
  fail "no joint states after the step"
stop_lockstep
csv="$out/a/drive.csv"
q=$(column "$csv" pan_q_rad)
max=$(awk -F, -v q="$q" 'NR>1 && $q>m {m=$q} END {printf "%.6f", m}' "$csv")
echo "pan reached $max rad against the live limit 0.2 rad (default 3.0)"
awk -v m="$max" 'BEGIN {exit !(m <= 0.201)}' || fail "pan passed the live soft limit: $max rad"
awk -v m="$max" 'BEGIN {exit !(m > 0.15)}' || fail "pan never neared the limit: $max rad"
echo PASS
