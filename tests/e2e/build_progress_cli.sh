#!/usr/bin/env bash
# haarcast-client shows the server's BuildProgress while a renderer is built
# on a cold cache: a real `haarcast serve` with an empty --cache-dir, a scene
# of one mesh of 29,040 vertices (written here), so that its visibility
# takes measurable time (about 3 s at level 5 on the 2-core development
# machine). The client's stderr must have
#   * plain lines (stderr is a file) "building: visibility blob  NN %", at
#     least two, with nondecreasing percentages, each with the whole build's
#     share and its step in the server's plan ("· build NN % (step 2 of 3)":
#     slices, visibility, and the point lights' finer slices),
#     nondecreasing too, and one with the build's estimated time left;
#   * "building: ready after N s" before the first frame line;
# then the same config again (the renderer is cached: no BuildProgress, and
# the client works as against a server that never sends it), and on a
# terminal (script(1), another level: a new build) one line redrawn in place
# ("\r…\x1b[K"). The outputs are printed, as an example of what a user sees.
#
# usage: build_progress_cli.sh HAARCAST HAARCAST_CLIENT
set -uo pipefail
server_bin="${1:?usage: build_progress_cli.sh HAARCAST HAARCAST_CLIENT}"
client_bin="${2:?usage: build_progress_cli.sh HAARCAST HAARCAST_CLIENT}"
work="$(mktemp -d -t haarcast-build-progress.XXXXXX)"
server_pid=""
cleanup() {
  [[ -n "$server_pid" ]] && { kill -KILL "$server_pid"; wait "$server_pid"; } 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT

failures=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }

# A bumpy sphere, 240 × 121 vertices: enough rays that visibility takes seconds.
python3 - "$work/blob.obj" <<'EOF'
import math, sys
nu, nv = 240, 120
with open(sys.argv[1], "w") as f:
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu):
            ph = 2 * math.pi * i / nu
            r = 1 + 0.15 * math.sin(5 * th) * math.cos(7 * ph)
            f.write(f"v {r * math.sin(th) * math.cos(ph):.5f} {r * math.cos(th):.5f} {r * math.sin(th) * math.sin(ph):.5f}\n")
    for j in range(nv):
        for i in range(nu):
            a, b = j * nu + i + 1, j * nu + (i + 1) % nu + 1
            c, d = a + nu, b + nu
            f.write(f"f {a} {c} {b}\nf {b} {c} {d}\n")
EOF
echo '{"objects": [{"name": "blob", "mesh": "blob.obj", "material": "phong:64"}]}' >"$work/blob.json"

source "$(dirname "${BASH_SOURCE[0]}")/start_server.sh"
start_server "$server_bin" serve --port 0 --quiet --cache-dir "$work/cache" --scene "$work/blob.json"
url="ws://127.0.0.1:$port/ws"
run=(--scene blob --frames 3 --size 64x64 --timeout 60)

# 1. Cold: the build's progress, then the frames.
rc=0
"$client_bin" "$url" "${run[@]}" --level 5 >/dev/null 2>"$work/cold.err" || rc=$?
echo "--- haarcast-client stderr, cold cache, not a terminal:"
cat "$work/cold.err"
[[ "$rc" == 0 ]] || fail "cold run exited $rc"
mapfile -t percents < <(sed -n 's/^building: visibility blob *\([0-9]*\) %.*/\1/p' "$work/cold.err")
((${#percents[@]} >= 2)) || fail "${#percents[@]} 'building: visibility blob NN %' lines, want at least 2"
for ((i = 1; i < ${#percents[@]}; i++)); do
  ((percents[i] >= percents[i - 1])) || fail "visibility went from ${percents[i - 1]} % to ${percents[i]} %"
done
mapfile -t builds < <(sed -n 's/^building: .* · build *\([0-9]*\) % (step [0-9]* of [0-9]*).*/\1/p' "$work/cold.err")
((${#builds[@]} >= 3)) || fail "${#builds[@]} lines with the build's share and step, want at least 3"
for ((i = 1; i < ${#builds[@]}; i++)); do
  ((builds[i] >= builds[i - 1])) || fail "the build went from ${builds[i - 1]} % to ${builds[i]} %"
done
grep -q '^building: visibility blob .* (step 2 of [0-9]*), ~[0-9.]* s left$' "$work/cold.err" ||
  fail "no line with the build's estimated time left"
ready_line="$(grep -n '^building: ready after [0-9.]* s$' "$work/cold.err" | head -1 | cut -d: -f1)"
frame_line="$(grep -n '^\[#*\.*\] [0-9]*/3' "$work/cold.err" | head -1 | cut -d: -f1)"
[[ -n "$ready_line" ]] || fail "no 'building: ready after N s' line"
[[ -n "$frame_line" ]] || fail "no frame progress line"
[[ -n "$ready_line" && -n "$frame_line" ]] && ((ready_line < frame_line)) ||
  fail "'building: ready' (line ${ready_line:-none}) must come before the frames (line ${frame_line:-none})"

# 2. The same config again: the server's cached renderer, nothing built.
rc=0
"$client_bin" "$url" "${run[@]}" --level 5 >/dev/null 2>"$work/warm.err" || rc=$?
[[ "$rc" == 0 ]] || { fail "warm run exited $rc:"; cat "$work/warm.err"; }
! grep -q '^building:' "$work/warm.err" || fail "a cached renderer showed build progress: $(grep '^building:' "$work/warm.err")"

# 3. On a terminal: one line redrawn in place (a new level: a new build).
if command -v script >/dev/null; then
  rc=0
  script -qec "$(printf '%q ' "$client_bin" "$url" "${run[@]}" --level 4) 2>&1" /dev/null >"$work/tty.out" </dev/null || rc=$?
  [[ "$rc" == 0 ]] || { fail "terminal run exited $rc:"; cat -v "$work/tty.out"; }
  echo "--- haarcast-client on a terminal (cat -v: ^M is \\r, ^[[K erases the rest of the line):"
  cat -v "$work/tty.out" | head -5
  grep -q $'\rbuilding: visibility blob .*\x1b\[K' "$work/tty.out" || fail "no redrawn 'building: visibility blob' line on the terminal"
  grep -q $'\rbuilding: ready after [0-9.]* s\x1b\[K' "$work/tty.out" || fail "no 'building: ready' line on the terminal"
else
  echo "(no script(1): the terminal display is not checked)"
fi

kill -TERM "$server_pid" && wait "$server_pid" || fail "the server did not exit 0 on SIGTERM"
server_pid=""
((failures == 0)) && echo "PASS" || exit 1
