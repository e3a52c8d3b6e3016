#!/usr/bin/env bash
# The fuzzing campaign (issue 20 section 3): every libFuzzer target of tests/fuzz for SECONDS
# each (default 600), one after another, then a table: target, executions, coverage (libFuzzer's
# cov: edges and ft: features), findings (crash, hang over 1 s, out-of-memory or leak inputs).
#   bash tools/fuzz.sh [SECONDS [TARGETS]]   (TARGETS: a regular expression of CTest names, e.g.
#                                             'sequencer|projector'; default all. AVS_BUILD_DIR:
#                                             the CMake build, default build)
# The targets, their seed corpora and the run limits are the CTest tests labelled `fuzz`
# (cmake/AvsFuzz.cmake); this script runs the same commands longer, in fork mode so that a
# finding is saved and the run goes on. Corpora grow in $BUILD/fuzz_campaign/<target>/corpus
# (the committed seeds are read, never written); findings land in .../findings/ and are kept
# in tests/fuzz/corpus/<parser>/ as regression inputs once fixed (docs/reliability.md).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
only=${2:-}
build=${AVS_BUILD_DIR:-build}
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] || { echo "usage: bash tools/fuzz.sh [SECONDS > 0 [TARGETS]]" >&2; exit 2; }
[ -f "$build/CMakeCache.txt" ] || { echo "fuzz.sh: no CMake build in $build (bash tools/run.sh test)" >&2; exit 2; }
cmake --build "$build" -j "${AVS_JOBS:-$(nproc)}" --target avs_fuzz_build >/dev/null
campaign=$(realpath "$build")/fuzz_campaign
mkdir -p "$campaign"

# One line per target: name, binary, its options (tab-separated), from CTest's own record.
ctest --test-dir "$build" -L fuzz ${only:+-R "$only"} --show-only=json-v1 | python3 -c '
import json, sys
for test in json.load(sys.stdin)["tests"]:
    command = test["command"]  # bash -c SCRIPT WORKDIR BINARY OPTIONS... new CORPUS...
    options = [a for a in command[5:] if not a.startswith(("-max_total_time=", "-seed="))]
    print("\t".join([test["name"], command[4]] + options))
' >"$campaign/targets.tsv"
[ -s "$campaign/targets.tsv" ] || { echo "fuzz.sh: no fuzz targets (clang missing? AVS_FUZZ=OFF?)" >&2; exit 1; }

rows=()
while IFS=$'\t' read -r name binary options; do
  dir=$campaign/$name
  rm -rf "$dir/findings" && mkdir -p "$dir/corpus" "$dir/findings"
  read -r -a args <<<"$options"
  seeds=()
  for a in "${args[@]}"; do [ -d "$a" ] && [ "$a" != new ] && seeds+=("$a"); done
  flags=()
  for a in "${args[@]}"; do [[ "$a" == -* ]] && flags+=("$a"); done
  echo "== $name: ${seconds} s"
  (cd "$dir" && "$binary" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -max_total_time="$seconds" -seed=1 -artifact_prefix="$dir/findings/" "${flags[@]}" \
    corpus "${seeds[@]}" >"$dir/log.txt" 2>&1) || true
  # Fork mode's status lines: "#EXECS: cov: C ft: F corp: N exec/s: E oom/timeout/crash: ..."
  last=$(grep -E '^#[0-9]+: cov: ' "$dir/log.txt" | tail -1 || true)
  execs=$(sed -E 's/^#([0-9]+):.*/\1/' <<<"$last")
  cov=$(sed -E 's/.* cov: ([0-9]+).*/\1/' <<<"$last")
  ft=$(sed -E 's/.* ft: ([0-9]+).*/\1/' <<<"$last")
  findings=$(find "$dir/findings" -type f | wc -l)
  rows+=("$(printf '| %-24s | %12s | %8s | %8s | %8s |' "$name" "${execs:-?}" "${cov:-?}" "${ft:-?}" "$findings")")
done <"$campaign/targets.tsv"

echo
echo "Fuzzing campaign: $seconds s per target, clang $(clang --version | sed -nE 's/.*version ([0-9.]+).*/\1/p' | head -1), seed 1"
printf '| %-24s | %12s | %8s | %8s | %8s |\n' target executions "cov" "ft" findings
echo "|--------------------------|--------------|----------|----------|----------|"
printf '%s\n' "${rows[@]}"
if [ "$(find "$campaign" -path '*/findings/*' -type f | wc -l)" -gt 0 ]; then
  echo "findings (reproduce: the target binary with the file as its argument):"
  find "$campaign" -path '*/findings/*' -type f | sort
  exit 1
fi
