#!/usr/bin/env bash
# `haarcast bench-frame` prints each table row when it is measured, not all
# at the end, and says on stderr how many rows are done and left: with
# stdout and stderr in one pipe (each line written as it happens), the first
# row must come before the second method is prepared, and every row's
# "row N of 4 …; M left" line must follow it.
#
# usage: bench_frame_progress.sh HAARCAST
set -uo pipefail
bin="${1:?usage: bench_frame_progress.sh HAARCAST}"
out="$(mktemp -t haarcast-bench-progress.XXXXXX)"
trap 'rm -f "$out"' EXIT

timeout 300 "$bin" bench-frame --backend cpu --sizes 16,24 --levels 3 --method fused,haar --frames 1 --warmup 0 \
  --cache-dir none >"$out" 2>&1
rc=$?
cat "$out"
failures=0
fail() { echo "FAIL $1"; failures=$((failures + 1)); }
[[ "$rc" == 0 ]] || fail "bench-frame exited $rc"

line_of() { grep -n -m1 -F -- "$1" "$out" | cut -d: -f1; }
first_row=$(line_of "| 3 | fused | cells τ 0.1, smooth ε 0.01 | 16×16 | cpu |")
haar_prepared=$(line_of "level 3, haar: preparing")
last_row=$(line_of "| 3 | haar | — | 24×24 | cpu |")
if [[ -z "$first_row" || -z "$haar_prepared" || -z "$last_row" ]]; then
  fail "the table rows and the preparing lines are all there"
elif ((first_row > haar_prepared)); then
  fail "the first row (line $first_row) is printed before haar is prepared (line $haar_prepared)"
else
  echo "ok   the first row (line $first_row) comes before haar is prepared (line $haar_prepared)"
fi
for n in 1 2 3 4; do
  left=$((4 - n))
  at=$(grep -n -m1 -E "^\[bench-frame\] row $n of 4 \(level 3, .*fps\); $left left, .* so far$" "$out" | cut -d: -f1)
  if [[ -z "$at" ]]; then
    fail "stderr says \"row $n of 4 …; $left left\""
  else
    echo "ok   row $n of 4, $left left (line $at)"
  fi
done
if ((failures > 0)); then
  echo "$failures check(s) failed"
  exit 1
fi
echo "all checks passed"
