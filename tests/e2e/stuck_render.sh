#!/usr/bin/env bash
# A render that never returns, end to end (docs/service.md, "Frame
# deadline"): `haarcast serve` with the test-only fault injection
# HAARCAST_TEST_STALL_STAGE=gbuffer, whose frames block for ever in stage
# gbuffer, deaf to cancellation.
#
#   1. Default deadline: a client's frame is stuck; SIGTERM must end the
#      server within 2 s with status 0, its log naming the stuck thread's
#      stage (the render thread is not joined).
#   2. --frame-deadline 1: the client gets an error naming the stage and the
#      device; /readyz answers 503 naming the device (the default backend's);
#      /metrics says device_healthy 0, one frame abandoned, one thread stuck;
#      the next frame fails at once; SIGTERM again within 2 s, status 0.
#
# usage: stuck_render.sh HAARCAST HAARCAST_CLIENT
set -uo pipefail
server_bin="${1:?usage: stuck_render.sh HAARCAST HAARCAST_CLIENT}"
client_bin="${2:?usage: stuck_render.sh HAARCAST HAARCAST_CLIENT}"
limit_s=2
work="$(mktemp -d -t haarcast-stuck.XXXXXX)"
server_pid="" client_pid=""
cleanup() {
  [[ -n "$client_pid" ]] && { kill -KILL "$client_pid"; wait "$client_pid"; } 2>/dev/null
  [[ -n "$server_pid" ]] && { kill -KILL "$server_pid"; wait "$server_pid"; } 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT
failures=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}

source "$(dirname "${BASH_SOURCE[0]}")/start_server.sh"
metric() { curl -s "http://127.0.0.1:$port/metrics" | sed -n "s/^$1 \([0-9.e+-]*\)$/\1/p"; }

# Waits until a frame renders (its pixels in flight), up to 120 s (the
# renderer's first build included).
wait_for_render() {
  local i pixels
  for ((i = 0; i < 1200; i++)); do
    pixels="$(metric haarcast_pixels_in_flight)"
    [[ "${pixels:-0}" -gt 0 ]] && return 0
    sleep 0.1
  done
  return 1
}

# SIGTERM to the server; checks status 0 within $limit_s and the log line
# naming the stuck render thread's stage.
sigterm_and_check() {
  local what="$1" start rc=124 i elapsed in_time
  start=$(date +%s.%N)
  kill -TERM "$server_pid"
  for ((i = 0; i < 200; i++)); do
    if ! kill -0 "$server_pid" 2>/dev/null; then
      wait "$server_pid"
      rc=$?
      break
    fi
    sleep 0.02
  done
  elapsed=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.2f}')" "$start" "$(date +%s.%N)")
  [[ "$rc" == 124 ]] && kill -KILL "$server_pid" 2>/dev/null
  server_pid=""
  echo "SIGTERM with $what: exit $rc after $elapsed s (limit $limit_s s)"
  in_time=$(python3 -c "import sys; print(int(float(sys.argv[1]) < float(sys.argv[2])))" "$elapsed" "$limit_s")
  [[ "$rc" == 0 && "$in_time" == 1 ]] || fail "SIGTERM with $what: exit $rc after $elapsed s"
  grep -q "in stage gbuffer on device cpu" "$work/server.err" ||
    fail "the log does not name the stuck thread's stage: $(tail -3 "$work/server.err")"
}

export HAARCAST_TEST_STALL_STAGE=gbuffer

# ---- 1. SIGTERM while a frame is stuck (default deadline) ------------------
start_server "$server_bin" serve --port 0 --backend cpu --level 4
"$client_bin" "ws://127.0.0.1:$port" --size 64x64 --frames 1 --quiet --timeout 300 \
  >"$work/client.out" 2>"$work/client.err" &
client_pid=$!
if wait_for_render; then
  sleep 0.2
  sigterm_and_check "a frame stuck in gbuffer"
else
  fail "no frame started rendering within 120 s: $(tail -3 "$work/server.err")"
fi
kill -KILL "$client_pid" 2>/dev/null
wait "$client_pid" 2>/dev/null
client_pid=""

# ---- 2. The deadline: the error, /readyz, /metrics, fail fast --------------
start_server "$server_bin" serve --port 0 --backend cpu --level 4 --frame-deadline 1
"$client_bin" "ws://127.0.0.1:$port" --size 64x64 --frames 1 --timeout 20 >"$work/client.out" 2>"$work/client.err"
grep -q "frame abandoned after 1 s in stage gbuffer on device cpu" "$work/client.err" ||
  fail "the client was not told the stage: $(cat "$work/client.err")"
code="$(curl -s -o "$work/readyz" -w '%{http_code}' "http://127.0.0.1:$port/readyz")"
echo "/readyz: $code $(cat "$work/readyz")"
[[ "$code" == 503 ]] && grep -q "^device unhealthy: cpu .* in stage gbuffer" "$work/readyz" ||
  fail "/readyz did not name the unhealthy device"
curl -s "http://127.0.0.1:$port/metrics" >"$work/metrics"
grep -q '^haarcast_device_healthy{backend="cpu",device="cpu[^"]*"} 0$' "$work/metrics" ||
  fail "/metrics: no unhealthy device: $(grep device_healthy "$work/metrics")"
[[ "$(metric haarcast_frames_abandoned_total)" == 1 ]] || fail "/metrics: frames abandoned $(metric haarcast_frames_abandoned_total)"
[[ "$(metric haarcast_render_threads_stuck)" == 1 ]] || fail "/metrics: threads stuck $(metric haarcast_render_threads_stuck)"
[[ "$(metric haarcast_pixels_in_flight)" == 0 ]] || fail "/metrics: the abandoned frame's pixels are still in flight"
start=$(date +%s.%N)
"$client_bin" "ws://127.0.0.1:$port" --size 64x64 --frames 1 --timeout 5 >"$work/client.out" 2>"$work/client2.err"
grep -q "is unhealthy: a frame abandoned after 1 s in stage gbuffer" "$work/client2.err" ||
  fail "the next frame did not fail naming the device: $(cat "$work/client2.err")"
sigterm_and_check "a thread left behind by the deadline"

if [[ "$failures" -gt 0 ]]; then
  echo "FAIL ($failures)"
  exit 1
fi
echo "passed"
