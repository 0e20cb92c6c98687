#!/usr/bin/env bash
# haarcast-client's failures, each with its exit code and a message that names
# the cause: bad flags (2), connection refused (1), a missing or wrong token
# (HTTP 401, 1), a server Error (1); and the good case (0). Then the server
# must exit 0 on SIGTERM.
#
# usage: client_errors.sh HAARCAST HAARCAST_CLIENT
set -uo pipefail
server_bin="${1:?usage: client_errors.sh HAARCAST HAARCAST_CLIENT}"
client_bin="${2:?usage: client_errors.sh HAARCAST HAARCAST_CLIENT}"
work="$(mktemp -d -t haarcast-client-errors.XXXXXX)"
server_pid=""
cleanup() {
  [[ -n "$server_pid" ]] && kill -KILL "$server_pid" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT

failures=0
# expect NAME WANT_RC WANT_TEXT -- command...: the exit code and a piece of stderr.
expect() {
  local name="$1" want_rc="$2" want_text="$3"
  shift 4
  local rc=0
  "$@" >"$work/out" 2>"$work/err" || rc=$?
  if [[ "$rc" != "$want_rc" ]] || ! grep -qF -- "$want_text" "$work/err"; then
    echo "FAIL $name: exit $rc (want $want_rc), stderr must contain \"$want_text\":"
    sed 's/^/    /' "$work/err"
    failures=$((failures + 1))
  else
    echo "ok   $name: exit $rc, \"$want_text\""
  fi
}

expect "bad --size" 2 "--size" -- "$client_bin" ws://127.0.0.1:1 --size 0x10
expect "bad --encoding" 2 "--encoding must be" -- "$client_bin" ws://127.0.0.1:1 --encoding webp
expect "--bitrate without h264" 2 "--bitrate applies to --encoding h264 only" -- "$client_bin" ws://127.0.0.1:1 --bitrate 900
expect "h264 at an odd size" 2 "even width and height" -- "$client_bin" ws://127.0.0.1:1 --encoding h264 --size 255x256
expect "wss:// refused" 2 "wss://" -- "$client_bin" wss://127.0.0.1:1
expect "bad --level" 2 "--level must be N, auto or auto:N, N a map level the server serves (got \"12x\")" -- "$client_bin" ws://127.0.0.1:1 --level 12x
expect "bad --exposure" 2 "--exposure must be auto or a number of stops" -- "$client_bin" ws://127.0.0.1:1 --exposure bright
expect "misspelt flag" 2 "unknown flag --frmes; did you mean --frames?" -- "$client_bin" ws://127.0.0.1:1 --frmes 3
# Without the url too: the unknown flag first (CLI11 checks the url first).
expect "unknown flag, no url" 2 "unknown flag --bogus" -- "$client_bin" --bogus
expect "unknown flag, no url: the url named" 2 "the server's url (ws://HOST:PORT) is missing" -- "$client_bin" --bogus
expect "connection refused" 1 "Connection refused" -- "$client_bin" ws://127.0.0.1:1 --frames 1 --quiet

# The server's --encoding takes the wire's names (wire::encodingName) of
# what it can send: not the enum's UNSPECIFIED.
expect "serve: bad --encoding" 2 "--encoding must be jpeg, png, raw, exr or h264 (got \"webp\")" -- \
  "$server_bin" serve --port 0 --encoding webp
expect "serve: --encoding unspecified" 2 "(got \"unspecified\")" -- "$server_bin" serve --port 0 --encoding unspecified

source "$(dirname "${BASH_SOURCE[0]}")/start_server.sh"
start_server "$server_bin" serve --port 0 --token sekret --backend "${HAARCAST_SMOKE_BACKEND:-cpu}"
url="ws://127.0.0.1:$port"
common=(--frames 2 --size 64x64 --quiet --timeout 60)
expect "no token" 1 "HTTP 401" -- "$client_bin" "$url" "${common[@]}"
expect "wrong token" 1 "wrong --token" -- "$client_bin" "$url" "${common[@]}" --token nope
expect "server Error (level over the server's --max-level)" 1 "is outside 2..6" -- \
  "$client_bin" "$url" "${common[@]}" --token sekret --level 7
expect "server Error (a level no renderer takes)" 1 "level 12 is outside 2..6" -- \
  "$client_bin" "$url" "${common[@]}" --token sekret --level 12
expect "server Error (a side over the server's)" 1 "resolution 9000x64 is outside 1x1.." -- \
  "$client_bin" "$url" --frames 2 --size 9000x64 --quiet --timeout 60 --token sekret
expect "good run, auto exposure, not blown out" 0 "" -- \
  "$client_bin" "$url" "${common[@]}" --token sekret --check-not-blank --max-clipped 0.02
expect "server Error (unknown material)" 1 "ERROR_CODE_UNKNOWN_MATERIAL" -- \
  "$client_bin" "$url" "${common[@]}" --token sekret --material 0=no-such-material
expect "good run" 0 "" -- "$client_bin" "$url" "${common[@]}" --token sekret --check-not-blank

# Two clients in one process playing a pose file: each records every pose's
# frame in its own folder, and the frames differ (the file moves the camera).
cat >"$work/path.json" <<'JSON'
{"poses": [{"camera": {"eye": [0, 0.6, 3.4]}},
           {"camera": {"eye": [2.4, 0.6, 2.4]}, "light_rotate_degrees": [0, 90, 0]},
           {"objects": [{"object": 1, "rotate_degrees": [0, 45, 0]}]}]}
JSON
expect "two clients, pose file" 0 "" -- "$client_bin" "$url" --token sekret --size 32x32 --clients 2 \
  --path "$work/path.json" --out "$work/frames" --check-not-blank --quiet --timeout 60
for c in 0 1; do
  n="$(find "$work/frames/client-$c" -type f -name 'frame-*.jpg' 2>/dev/null | wc -l)"
  distinct="$(cksum "$work/frames/client-$c"/* 2>/dev/null | awk '{print $1}' | sort -u | wc -l)"
  if [[ "$n" != 3 || "$distinct" -lt 2 ]]; then
    echo "FAIL client-$c recorded $n frames ($distinct distinct), want 3 (the file's length), not all equal"
    failures=$((failures + 1))
  else
    echo "ok   client-$c recorded the file's 3 poses ($distinct distinct frames)"
  fi
done

# Sixteen clients in one process against the server's default caps (8
# connections per address before their Hello): the client keeps at most 4
# waiting for the server's first answer, so every one gets its frames.
expect "sixteen clients, default caps" 0 "" -- "$client_bin" "$url" --token sekret --size 32x32 --clients 16 \
  --frames 2 --quiet --timeout 60

kill -TERM "$server_pid"
rc=""
for ((i = 0; i < 300; i++)); do
  if ! kill -0 "$server_pid" 2>/dev/null; then
    rc=0
    wait "$server_pid" || rc=$?
    break
  fi
  sleep 0.1
done
server_pid_done="$server_pid"
server_pid=""
if [[ "$rc" != 0 ]]; then
  echo "FAIL the server (pid $server_pid_done) exited '${rc:-still running}' after SIGTERM, want 0"
  kill -KILL "$server_pid_done" 2>/dev/null
  failures=$((failures + 1))
else
  echo "ok   the server exited 0 on SIGTERM"
fi
((failures == 0)) || { echo "$failures check(s) failed"; exit 1; }
echo "all checks passed"
