#!/usr/bin/env bash
# A torque step through the whole chain (test source -> servo_drive -> Modbus TCP ->
# sim_amplifier plant) accelerates each axis as the plant's law says,
#   J q'' = eta N tau - b q' - Fc sign(q')   (docs/servo.md section 5),
# and the run is deterministic: a second run with both cores loaded gives identical reports.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration_servo/lib.sh"
out=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$out"' EXIT
args=(duration_s:=0.4 "torque_nm:=[0.5, 0.1]" step_at_s:=0.1 step_until_s:=0.12)

run_head "$out/a" "${args[@]}"
for i in 1 2; do (while :; do :; done) & done   # load both cores
run_head "$out/b" "${args[@]}"
kill $(jobs -p)
for f in drive.csv drive.yaml recorder_sim.csv recorder_joints.csv; do
  cmp -s "$out/a/$f" "$out/b/$f" || { diff "$out/a/$f" "$out/b/$f" | head -5; fail "$f differs between runs"; }
done
cat "$out/a/drive.yaml"
[ "$(value "$out/a/drive.yaml" cycles)" -eq 399 ] || fail "expected 399 drive cycles"
[ "$(value "$out/a/drive.yaml" link_fault_cycles)" -eq 0 ] || fail "link faults in a clean run"

# Mean acceleration over the torque-on window, from the true plant state (/sim/head_state)
# and from the drive's encoder feedback (/head/joint_states), against the model evaluated with
# the applied motor torque (effort column) at the window's mean speed. Tolerance 1 % (plant),
# 2 % (encoder).
check_axis() {  # file, axis, J, b, Fc, tolerance
  local file=$1 axis=$2 J=$3 b=$4 Fc=$5 tol=$6
  local q=$(column "$out/a/recorder_sim.csv" "${axis}_qd_rad_s") e=$(column "$out/a/recorder_sim.csv" "${axis}_effort_nm")
  # applied torque while the step is on (the drive applies it from 0.101 s, the plant from 0.102)
  local tau=$(awk -F, -v e="$e" 'NR>1 && $1>0.105 && $1<0.115 {print $e; exit}' "$out/a/recorder_sim.csv")
  awk -F, -v c="$q" -v tau="$tau" -v J="$J" -v b="$b" -v Fc="$Fc" -v tol="$tol" -v name="$axis ($file)" '
    NR>1 && $1>=0.1045 && $1<=0.1055 {t0=$1; v0=$c}
    NR>1 && $1>=0.1145 && $1<=0.1155 {t1=$1; v1=$c}
    END {
      if (t1 <= t0 || tau <= 0) { print "FAIL: no torque-on window for " name; exit 1 }
      measured = (v1 - v0) / (t1 - t0)
      expected = (0.95 * 4.2 * tau - Fc - b * (v0 + v1) / 2) / J
      rel = measured / expected - 1
      printf "%s: tau %.5f N m, acceleration %.2f rad/s^2, model %.2f (%+.3f %%), eta N tau / J = %.1f\n", name, tau, measured, expected, 100 * rel, 0.95 * 4.2 * tau / J
      if (rel > tol || rel < -tol) { print "FAIL: " name " acceleration off by more than " 100 * tol " %"; exit 1 }
    }' "$out/a/$file"
}
check_axis recorder_sim.csv pan 0.00598 0.02 0.4 0.01
check_axis recorder_sim.csv tilt 0.00117 0.005 0.07 0.01
check_axis recorder_joints.csv pan 0.00598 0.02 0.4 0.02
check_axis recorder_joints.csv tilt 0.00117 0.005 0.07 0.02

# Before the step nothing moves; after it the head coasts to rest (friction).
awk -F, 'NR>1 && $1<0.1 && ($2!=0 || $5!=0) {print "FAIL: head moved before the step at t=" $1; exit 1}' "$out/a/recorder_sim.csv"
last=$(tail -1 "$out/a/recorder_sim.csv")
awk -F, '{ if ($3!=0 || $6!=0) { print "FAIL: head still moving at the end: " $0; exit 1 } }' <<<"$last"

# The explicit YAML register map equal to the default (docs/servo.md) gives the same run.
run_head "$out/c" "${args[@]}" register_map:="$src/tests/integration_servo/data/sim_map.yaml"
cmp -s "$out/a/drive.csv" "$out/c/drive.csv" || { diff "$out/a/drive.csv" "$out/c/drive.csv" | head -5; fail "sim_map.yaml run differs from the default map"; }
echo PASS
