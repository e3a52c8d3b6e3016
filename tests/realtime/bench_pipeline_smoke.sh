#!/usr/bin/env bash
# Smoke test of `avs bench pipeline`: 1 s per placement (intra_process, udp, and shm when
# iox-roudi is installed and no RouDi runs), then the JSON object must carry the stable keys of
# every placement measured, and poses must have come out of each. Speed, rates, drops and
# latency are the benchmark's figures on a loaded machine, never checked here.
# Usage: bench_pipeline_smoke.sh AVS
set -u
AVS=${1:?avs binary}
. "$(dirname "${BASH_SOURCE[0]}")/../support/test_domain.sh"  # AVS_DOMAIN_ID of its own
W=$(mktemp -d /tmp/avs_bench_pipeline.XXXXXX)
trap 'rm -rf "$W"' EXIT
fail() { echo "FAIL: $*"; tail -n 30 "$W/bench.log"; exit 1; }

if [ "${AVS_BENCHMARKS:-1}" != 1 ]; then
  "$AVS" bench pipeline >"$W/bench.log" 2>&1 && fail "avs bench pipeline succeeded without benchmarks"
  grep -q "built without benchmarks" "$W/bench.log" || fail "no clear message without benchmarks"
  echo "PASS: avs bench pipeline says it was not built (AVS_BUILD_BENCHMARKS=OFF)"
  exit 0
fi

placements=intra_process,udp
if command -v iox-roudi >/dev/null && ! pgrep -x iox-roudi >/dev/null; then placements+=,shm; fi
"$AVS" bench pipeline --json --seconds=1 --recorded-frames=90 --placements=$placements \
  --dir="$W/out" >"$W/bench.json" 2>"$W/bench.log" || fail "avs bench pipeline --json failed"
json=$(tail -n 1 "$W/bench.json")
echo "$json"
[[ $json == \{*\} ]] || fail "the last line is not one JSON object: $json"
python3 - "$json" "$placements" <<'PY' || fail "JSON shape"
import json, sys
d = json.loads(sys.argv[1])
for p in sys.argv[2].split(","):
    for k in ("latency_ms_p50", "latency_ms_p99", "latency_ms_max", "depth_rate_hz",
              "pose_rate_hz", "dropped_inputs", "cpu_percent", "poses", "depth_maps"):
        key = f"placement.{p}.{k}"
        if key not in d:
            sys.exit(f"missing key {key}")
    if d[f"placement.{p}.depth_maps"] < 1 or d[f"placement.{p}.poses"] < 1:
        sys.exit(f"{p}: no depth maps or no poses came out")
for k in ("load_average_1min_before", "seconds_per_placement", "source_closed_loop"):
    if k not in d:
        sys.exit(f"missing key {k}")
if d["source_closed_loop"] != 1:
    sys.exit("the default source is not the closed loop's recording")
for p in sys.argv[2].split(","):
    if f"placement.{p}.source_late_frames" not in d:
        sys.exit(f"missing key placement.{p}.source_late_frames")
PY
for f in latency_histogram.png latency_over_time.png latency_intra_process.csv; do
  [ -s "$W/out/$f" ] || fail "$f not written"
done

# The default source is recorded from the lockstep closed loop first (the head follows the
# ken): the recording is in the output folder, and the replay read whole cycles of it.
[ -s "$W/out/closed_loop.mcap" ] || fail "no closed-loop recording in the output folder"
grep -q "read 90 frames (5 cycles of 18) of .*closed_loop.mcap" "$W/bench.log" ||
  fail "the source did not read 5 whole cycles of the recording"

# The table form, replaying that recording (--bag) beside a CPU hog (--cpu-load): the paper
# beside ours, and the load average.
"$AVS" bench pipeline --seconds=1 --recorded-frames=90 --placements=intra_process \
  --bag="$W/out/closed_loop.mcap" --cpu-load=1 --dir="$W/out2" >"$W/table.txt" 2>"$W/bench.log" ||
  fail "avs bench pipeline (table) failed"
grep -q "1 CPU hog process(es) beside it" "$W/table.txt" || fail "the CPU hog is not said"
[ -e "$W/out2/closed_loop.mcap" ] && fail "--bag recorded the closed loop again"
grep -q "recorded in the closed loop: $W/out/closed_loop.mcap" "$W/table.txt" ||
  fail "the table does not name the recording replayed"
"$AVS" bench pipeline --bag="$W/nonexistent.mcap" >"$W/bad.txt" 2>&1 &&
  fail "a missing --bag file was accepted"
grep -q "no such file" "$W/bad.txt" || fail "a missing --bag file is not named: $(cat "$W/bad.txt")"
grep -q "paper" "$W/table.txt" || fail "no paper figures beside ours"
grep -q "load average" "$W/table.txt" || fail "no load average printed"
echo "PASS: avs bench pipeline ($placements)"
