#!/usr/bin/env bash
# Issue 20 section 2: malformed /head/torque_command samples (a NaN torque, fewer torques than
# joint names, in turn) from 0.2 s to 0.21 s. servo_drive rejects each one with its reason,
# counts it (rejected_samples on /diagnostics, rejected_commands in the report) and logs it
# rate-limited; the last valid command stays (within the stale-command limit), no NaN reaches
# the drive, and the graph runs to its end.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration_servo/lib.sh"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
run_head "$out/a" duration_s:=0.3 "torque_nm:=[0.05, 0.01]" step_at_s:=0.05 step_until_s:=10 \
  bad_from_s:=0.2 bad_until_s:=0.21
csv="$out/a/drive.csv"
log="$out/a/stderr.txt"
rejected=$(value "$out/a/drive.yaml" rejected_commands)
echo "rejected_commands: $rejected"
[ "$rejected" -ge 9 ] && [ "$rejected" -le 11 ] || fail "rejected_commands $rejected, expected the 10 malformed ones"
if grep -qi "nan" "$csv"; then fail "a NaN in the drive's report"; fi
awk -F, 'NR>1 && $1>=0.15 && ($5!=0.05 || $10!=0.01) {print "FAIL: the last valid command was not kept: " $0; exit 1}' "$csv"
[ "$(grep -c 'torque_command rejected' "$log")" -eq 5 ] || fail "not the 5 log lines of a rate-limited rejection"
grep -q "torque 0 is not finite" "$log" || fail "no reason for the NaN"
grep -q "1 torques for 2 names" "$log" || fail "no reason for the short command"
last=$(awk -F, 'END {print $1}' "$csv")
awk -v t="$last" 'BEGIN {exit !(t >= 0.29)}' || fail "the run ended early at $last"
echo PASS
