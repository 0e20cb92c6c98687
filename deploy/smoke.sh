#!/usr/bin/env bash
# Smoke test of the service, headless. Builds nothing: it expects
# $BUILD_DIR/bin/haarcast and $BUILD_DIR/bin/haarcast-client.
#
#   deploy/smoke.sh               start `haarcast serve --port 0` (Vulkan: lavapipe
#                                 without a GPU), wait for /healthz, play N frames
#                                 with haarcast-client, check them, SIGTERM, exit 0?
#   deploy/smoke.sh --url URL     the same checks against a running server (no
#                                 start, no stop): the container's HEALTHCHECK
#
# Environment:
#   BUILD_DIR               build folder (default: build)
#   SMOKE_FRAMES            frames to play (default 20)
#   SMOKE_SIZE              WIDTHxHEIGHT (default 64x64)
#   SMOKE_ENCODING          jpeg | png | raw | exr (default jpeg)
#   SMOKE_TIMEOUT           seconds for the server to listen / be healthy / stop (default 120)
#   HAARCAST_SMOKE_BACKEND  vulkan | cpu: skips the Vulkan device probe
#   HAARCAST_TOKEN          passed to the server (--token) and the client
#   SMOKE_OUT               keep frames and logs here (default: a temporary folder)
# Exit status: 0 when every check passed, 1 otherwise (the failing check is named).
set -euo pipefail

BUILD_DIR="${BUILD_DIR:-build}"
FRAMES="${SMOKE_FRAMES:-20}"
SIZE="${SMOKE_SIZE:-64x64}"
ENCODING="${SMOKE_ENCODING:-jpeg}"
TIMEOUT="${SMOKE_TIMEOUT:-120}"
TOKEN="${HAARCAST_TOKEN:-}"
URL=""
if [[ "${1:-}" == "--url" ]]; then
  URL="${2:?--url needs ws://HOST:PORT}"
elif (($# > 0)); then
  echo "usage: deploy/smoke.sh [--url ws://HOST:PORT]" >&2
  exit 2
fi

log() { printf 'smoke: %s\n' "$*"; }
fail() {
  printf 'smoke: FAIL: %s\n' "$*" >&2
  exit 1
}

server_bin="$BUILD_DIR/bin/haarcast"
client_bin="$BUILD_DIR/bin/haarcast-client"
[[ -x "$client_bin" ]] || fail "no $client_bin (build first: deploy/run.sh build)"
[[ -n "$URL" || -x "$server_bin" ]] || fail "no $server_bin (build first: deploy/run.sh build)"

work="${SMOKE_OUT:-}"
if [[ -z "$work" ]]; then
  work="$(mktemp -d -t haarcast-smoke.XXXXXX)"
  trap 'rm -rf "$work"' EXIT
fi
mkdir -p "$work/frames"
rm -f "$work"/frames/*

# GET http://HOST:PORT/PATH with bash alone (no curl in the image): prints
# the status line and body.
http_get() {
  local host="$1" port="$2" path="$3"
  exec 3<>"/dev/tcp/$host/$port" || return 1
  printf 'GET %s HTTP/1.1\r\nHost: %s:%s\r\nConnection: close\r\n\r\n' "$path" "$host" "$port" >&3
  timeout 10 cat <&3
  exec 3<&- 3>&-
}

server_pid=""
stop_server() {
  if [[ -n "$server_pid" ]] && kill -0 "$server_pid" 2>/dev/null; then kill -KILL "$server_pid" 2>/dev/null || true; fi
}

if [[ -z "$URL" ]]; then
  # The backend: Vulkan whenever a Vulkan device exists (lavapipe counts), the
  # CPU renderer only when there is none, and then loudly.
  backend="${HAARCAST_SMOKE_BACKEND:-}"
  if [[ -z "$backend" ]]; then
    if command -v vulkaninfo >/dev/null 2>&1 && vulkaninfo --summary 2>/dev/null | grep -q 'deviceName'; then
      backend=vulkan
      log "Vulkan device: $(vulkaninfo --summary 2>/dev/null | grep -m1 deviceName | sed 's/.*= //')"
    else
      backend=cpu
      echo "smoke: ************************************************************" >&2
      echo "smoke: WARNING: no Vulkan device (vulkaninfo found none):" >&2
      echo "smoke: WARNING: falling back to --backend cpu. Install mesa-vulkan-drivers." >&2
      echo "smoke: ************************************************************" >&2
    fi
  fi
  args=(serve --port 0 --backend "$backend")
  [[ -n "$TOKEN" ]] && args+=(--token "$TOKEN")
  log "starting $server_bin ${args[*]}"
  "$server_bin" "${args[@]}" >"$work/server.out" 2>"$work/server.err" </dev/null &
  server_pid=$!
  trap 'stop_server; [[ -z "${SMOKE_OUT:-}" ]] && rm -rf "$work"' EXIT

  # "listening on http://127.0.0.1:PORT/" once bound.
  port=""
  for ((i = 0; i < TIMEOUT * 10; i++)); do
    port="$(sed -n 's#.*listening on http://[^:]*:\([0-9]*\)/.*#\1#p' "$work/server.out" | head -1)"
    [[ -n "$port" ]] && break
    kill -0 "$server_pid" 2>/dev/null || { cat "$work/server.err" >&2; fail "the server exited before listening"; }
    sleep 0.1
  done
  [[ -n "$port" ]] || { cat "$work/server.err" >&2; fail "the server printed no 'listening on' line in ${TIMEOUT} s"; }
  host=127.0.0.1
  URL="ws://$host:$port"
else
  hostport="${URL#ws://}"
  hostport="${hostport%%/*}"
  host="${hostport%:*}"
  port="${hostport##*:}"
fi
log "server at $URL"

# /healthz answers "ok" once the server is ready for sessions.
healthy=0
answer=""
for ((i = 0; i < TIMEOUT * 2; i++)); do
  answer="$(http_get "$host" "$port" /healthz 2>&1 | tail -1)" || true
  if [[ "$answer" == "ok" ]]; then
    healthy=1
    break
  fi
  # A server started here that is gone will not answer: say so now, with its log.
  if [[ -n "$server_pid" ]] && ! kill -0 "$server_pid" 2>/dev/null; then
    wait "$server_pid" 2>/dev/null && status=0 || status=$?
    tail -20 "$work/server.err" >&2 2>/dev/null || true
    fail "the server exited (status $status) before /healthz answered ok"
  fi
  sleep 0.5
done
if ((!healthy)); then
  [[ -n "$server_pid" ]] && tail -20 "$work/server.err" >&2 2>/dev/null
  fail "/healthz did not answer ok within ${TIMEOUT} s (its last answer: \"${answer:-none}\")"
fi
log "/healthz ok"

client_args=("$URL" --frames "$FRAMES" --size "$SIZE" --encoding "$ENCODING" --orbit 90 --light 45
  --check-not-blank --out "$work/frames" --json --quiet --timeout "$TIMEOUT")
[[ -n "$TOKEN" ]] && client_args+=(--token "$TOKEN")
log "haarcast-client ${client_args[*]}"
client_rc=0
"$client_bin" "${client_args[@]}" >"$work/summary.json" 2>"$work/client.err" || client_rc=$?
cat "$work/client.err" >&2
((client_rc == 0)) || fail "haarcast-client exited $client_rc"

# The summary's top-level keys, indented by two spaces in the client's JSON.
field() { sed -n "s/^  \"$1\": \"\{0,1\}\([^\",]*\)\"\{0,1\},\{0,1\}$/\1/p" "$work/summary.json" | head -1; }
frames="$(field frames)"
fps="$(field fps)"
bytes="$(field bytes_per_frame)"
p50="$(field latency_ms_p50)"
errors="$(field errors)"
blank="$(field blank_frames)"
log "frames $frames, fps $fps, bytes/frame $bytes, latency p50 $p50 ms, errors $errors, blank $blank"
[[ "$frames" == "$FRAMES" ]] || fail "frames = '$frames', expected $FRAMES"
awk -v v="$fps" 'BEGIN { exit !(v > 0) }' || fail "fps = '$fps', expected > 0"
awk -v v="$bytes" 'BEGIN { exit !(v > 0) }' || fail "bytes_per_frame = '$bytes', expected > 0"
awk -v v="$p50" 'BEGIN { exit !(v > 0) }' || fail "latency_ms_p50 = '$p50', expected > 0"
[[ "$errors" == 0 ]] || fail "errors = '$errors', expected 0"
[[ "$blank" == 0 ]] || fail "blank_frames = '$blank', expected 0"
recorded="$(find "$work/frames" -type f | wc -l)"
((recorded == FRAMES)) || fail "$recorded frames recorded in $work/frames, expected $FRAMES"
# The frames differ from one another (the path moves the camera and light).
distinct="$(cksum "$work"/frames/* | awk '{print $1}' | sort -u | wc -l)"
((distinct > 1)) || fail "all $recorded recorded frames are identical"
log "$recorded frames recorded, $distinct distinct, none blank"

if [[ -n "$server_pid" ]]; then
  log "stopping the server (SIGTERM)"
  kill -TERM "$server_pid"
  rc=""
  for ((i = 0; i < TIMEOUT * 10; i++)); do
    if ! kill -0 "$server_pid" 2>/dev/null; then
      rc=0
      wait "$server_pid" || rc=$?
      break
    fi
    sleep 0.1
  done
  [[ -n "$rc" ]] || { stop_server; fail "the server did not exit within ${TIMEOUT} s of SIGTERM"; }
  server_pid=""
  ((rc == 0)) || { cat "$work/server.err" >&2; fail "the server exited $rc after SIGTERM, expected 0"; }
  log "the server exited 0"
fi
log "PASS"
