#!/usr/bin/env bash
# Closed visual-servo loop in lockstep (tests/support/graphs/servo_tracking_loop.yaml): a sphere
# swinging laterally at up to 1 m/s at 1 m, depth images through the true head angles,
# tracking -> servo_drive -> Modbus -> simulated head. With tracking the target stays in view
# for the whole run and the centroid error RMS is at most 20 px; without tracking (the head
# holds) the target leaves the view. The tracking run is repeated: identical reports.
set -euo pipefail
avs=$1; src=$2
. "$src/tests/integration_servo/lib.sh"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
loop="$src/tests/support/graphs/servo_tracking_loop.yaml"
run_loop() {  # dir, args...
  local dir=$1; shift
  mkdir -p "$dir"
  "$avs" launch "$loop" port:=$port report_dir:="$dir" "$@" 2>"$dir/stderr.txt" ||
    { cat "$dir/stderr.txt" >&2; fail "avs launch $loop $* failed"; }
}
stats() {  # tracking.csv -> "in_view_fraction rms_px"
  awk -F, 'NR>1 && $1>=0.2 {n++; if ($2==1) {k++; du=$4-255.5; dv=$5-255.5; s+=du*du+dv*dv}}
           END {printf "%.4f %.2f\n", k/n, k ? sqrt(s/k) : 0}' "$1"
}
run_loop "$out/on"
run_loop "$out/on2"
run_loop "$out/off" tracking:=false
cmp -s "$out/on/tracking.csv" "$out/on2/tracking.csv" || fail "tracking runs differ"
cmp -s "$out/on/drive.csv" "$out/on2/drive.csv" || fail "drive reports differ"
read -r on_view on_rms <<<"$(stats "$out/on/tracking.csv")"
read -r off_view off_rms <<<"$(stats "$out/off/tracking.csv")"
echo "tracking:    in_view_fraction $on_view centroid_error_px_rms $on_rms"
echo "no tracking: in_view_fraction $off_view centroid_error_px_rms $off_rms"
awk -v v="$on_view" -v r="$on_rms" 'BEGIN {exit !(v == 1 && r <= 20)}' ||
  fail "tracking: target not kept in view with RMS <= 20 px"
awk -v v="$off_view" 'BEGIN {exit !(v < 0.9)}' || fail "no tracking: the target did not leave the view"
[ "$(value "$out/on/drive.yaml" link_fault_cycles)" -eq 0 ] || fail "link faults in the loop"
echo PASS
