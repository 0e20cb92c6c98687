#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz with clang (ASan + UBSan) into
# build-sanitize/ and runs each for a while from its committed seed corpus.
#
#   deploy/fuzz.sh [--seconds N] [target …]   N seconds per target (default 20);
#                                            targets default to all of them
#
# Prints per target: executions, crashes, and the path of each crash input
# (build-sanitize/artifacts/<target>/). A target stops at its first crash; rerun
# one input with build-sanitize/fuzz/<target> <file>. New inputs the fuzzer finds
# go to build-sanitize/corpus/<target>/, never into the committed corpus.
# Environment: HAARCAST_JOBS (build jobs, and targets run at once; default nproc), HAARCAST_SANITIZE_DIR
# (default build-sanitize). Exits 1 when any target crashed.
set -euo pipefail

cd "$(dirname "$(readlink -f "${BASH_SOURCE[0]}")")/.."
seconds=20
targets=()
while (($# > 0)); do
  case "$1" in
    --seconds)
      [[ "${2:-}" =~ ^[0-9]+$ && "$2" -gt 0 ]] || { echo "error: --seconds needs a positive whole number" >&2; exit 2; }
      seconds="$2"
      shift 2
      ;;
    -h | --help)
      awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0" >&2
      exit 2
      ;;
    *)
      targets+=("$1")
      shift
      ;;
  esac
done
all=(fuzz_hdr fuzz_pfm fuzz_exr fuzz_ply fuzz_obj fuzz_merl fuzz_scene fuzz_protocol fuzz_websocket fuzz_http2)
((${#targets[@]} > 0)) || targets=("${all[@]}")
for t in "${targets[@]}"; do
  [[ " ${all[*]} " == *" $t "* ]] || { echo "error: unknown target '$t' (one of: ${all[*]})" >&2; exit 2; }
done
command -v clang++ >/dev/null || { echo "error: clang++ not found (apt-get install clang libfuzzer-14-dev)" >&2; exit 1; }

# The targets live in the one sanitized build (deploy/sanitize_build.sh).
dir="${HAARCAST_SANITIZE_DIR:-build-sanitize}"
deploy/sanitize_build.sh "${targets[@]}"

# A single request over 2 GiB is a finding (a header trusted before the data),
# as are 10 s on one input and a leak.
fuzz_one() {
  local t="$1" work="$dir/corpus/$1" artifacts="$dir/artifacts/$1"
  # Crash inputs of this run only: an earlier run's would be counted again.
  rm -rf "$artifacts"
  mkdir -p "$work" "$artifacts"
  "$dir/fuzz/$t" -max_total_time="$seconds" -rss_limit_mb=2560 -malloc_limit_mb=2048 -timeout=10 \
    -print_final_stats=1 -artifact_prefix="$artifacts/" "$work" "tests/fuzz/corpus/$t" >"$dir/artifacts/$t.log" 2>&1 </dev/null || true
}
# One target per core at a time (each fuzzer is one process, one thread);
# the table is printed in the targets' order once they have all run.
jobs="${HAARCAST_JOBS:-$(nproc)}"
running=0
for t in "${targets[@]}"; do
  if ((running >= jobs)); then
    wait -n || true
    running=$((running - 1))
  fi
  fuzz_one "$t" &
  running=$((running + 1))
done
wait || true
failed=0
printf '%-15s %12s %8s  %s\n' target executions crashes "crash inputs"
for t in "${targets[@]}"; do
  artifacts="$dir/artifacts/$t"
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$dir/artifacts/$t.log" | tail -n 1)"
  crashes=("$artifacts"/*)
  [[ -e "${crashes[0]}" ]] || crashes=()
  ((${#crashes[@]} == 0)) || failed=1
  printf '%-15s %12s %8s  %s\n' "$t" "${execs:-?}" "${#crashes[@]}" "${crashes[*]:-}"
done
((failed == 0)) || echo "crash details: $dir/artifacts/<target>.log" >&2
exit "$failed"
