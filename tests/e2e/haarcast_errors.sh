#!/usr/bin/env bash
# `haarcast`'s errors for what a user mistypes: each exits 2 before any work
# starts, with a message that names the problem and the valid choices.
#
# usage: haarcast_errors.sh HAARCAST
set -uo pipefail
bin="${1:?usage: haarcast_errors.sh HAARCAST}"
work="$(mktemp -d -t haarcast-errors.XXXXXX)"
trap 'rm -rf "$work"' EXIT

failures=0
# expect NAME WANT_TEXT -- command...: exit 2 and a piece of stderr.
expect() {
  local name="$1" want_text="$2"
  shift 3
  local rc=0
  timeout 60 "$@" >"$work/out" 2>"$work/err" </dev/null || rc=$?
  if [[ "$rc" != 2 ]] || ! grep -qF -- "$want_text" "$work/err"; then
    echo "FAIL $name: exit $rc (want 2), stderr must contain \"$want_text\":"
    sed 's/^/    /' "$work/err"
    failures=$((failures + 1))
  else
    echo "ok   $name: \"$want_text\""
  fi
}

expect "misspelt command" 'unknown command "rendr"; did you mean render?' -- "$bin" rendr
expect "commands listed" "commands: rotation-report, render, reference, eval, bench-frame, serve" -- "$bin" rendr
expect "a bare haarcast lists its commands" "bench-frame      Per-pass and frame times" -- "$bin"
expect "a bare haarcast says how to see flags" "\`haarcast COMMAND --help\` lists a command's flags" -- "$bin"
expect "misspelt flag" "haarcast render: error: unknown flag --widht; did you mean --width?" -- \
  "$bin" render --widht 64 --out "$work/x.exr"
expect "misspelt flag with =" "unknown flag --levle; did you mean --levels?" -- "$bin" bench-frame --levle=4
expect "two misspelt flags" "unknown flag --heigth; did you mean --height?" -- \
  "$bin" render --widht 64 --heigth 32 --out "$work/x.exr"
expect "port out of range" "--port: Value 99999 not in range 0 to 65535" -- "$bin" serve --port 99999
expect "backend not offered" '--backend "gpu" is not a backend (valid: cpu' -- "$bin" serve --backend gpu
expect "missing web root" "--web-root $work/none: no such folder" -- "$bin" serve --web-root "$work/none"
expect "max level outside the range" "--max-level 9 is outside 2..7" -- "$bin" serve --max-level 9
expect "serve level over --max-level" "--level 7 is outside 2..6 (see --max-level)" -- "$bin" serve --level 7
expect "render level outside the range" '--level must be N (2..7: every object at level N), auto (' -- \
  "$bin" render --level 8 --out "$work/x.exr"
expect "render level neither a number nor auto" 'or auto:CAP (at most CAP, 2..7) (got "fine")' -- \
  "$bin" render --level fine --out "$work/x.exr"
expect "bench-frame level cap outside the range" '--levels: "auto:9" is not N (2..7' -- "$bin" bench-frame --levels 5,auto:9
expect "bench-frame sum tolerance outside 0..1" '--sum-tolerance: "2" is not a number in 0..1' -- "$bin" bench-frame --backend cpu --sum-tolerance 0,2
expect "bench-frame smooth-sum tolerance outside 0..1" '--smooth-sum: "2" is not a number in 0..1' -- "$bin" bench-frame --backend cpu --smooth-sum 0,2
expect "bench-frame frames in flight outside 1..16" '--in-flight: "0" is not a count of frames in 1..16' -- "$bin" bench-frame --backend vulkan --in-flight 1,0
expect "bench-frame fused workgroup size not a power of two" "--fused-local-size: 48 not in {0,1,2,4" -- \
  "$bin" bench-frame --backend vulkan --fused-local-size 48
expect "bench-frame frames in flight on the CPU backend" "--in-flight measures the Vulkan backend's frames in flight" -- \
  "$bin" bench-frame --backend cpu --in-flight 2
expect "serve queues over 16" "--vulkan-queues: Value 17 not in range 0 to 16" -- "$bin" serve --vulkan-queues 17
expect "serve level cap over --max-level" "--level auto:7 is outside 2..6 (see --max-level)" -- "$bin" serve --level auto:7
expect "unknown method" "--method must be one of fused" -- "$bin" render --method fast --out "$work/x.exr"
expect "material without a mesh" "--material applies to --mesh" -- "$bin" render --material velvet --out "$work/x.exr"
expect "output folder missing" "--out $work/none/x.exr: the folder $work/none does not exist" -- \
  "$bin" render --out "$work/none/x.exr"
expect "output extension" "--out must end in .exr or .png" -- "$bin" render --out "$work/x.jpg"
expect "bad --up" "--up x is not an up axis (valid: y, z)" -- "$bin" render --mesh "$work/none.obj" --up x --out "$work/x.exr"
expect "--up without --mesh" "--up applies to --mesh" -- "$bin" render --up z --out "$work/x.exr"
expect "unknown scene file" "$work/none.json" -- "$bin" serve --scene "$work/none.json"

# Checked before the work: no output was started for any of the above.
if compgen -G "$work/*.exr" >/dev/null || compgen -G "$work/*.png" >/dev/null; then
  echo "FAIL an output file was written by a command that failed"
  failures=$((failures + 1))
fi
if ((failures > 0)); then
  echo "$failures check(s) failed"
  exit 1
fi
