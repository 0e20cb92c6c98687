#!/usr/bin/env bash
# SIGTERM while `haarcast serve` renders the largest frames it allows (issue
# 12: "SIGTERM exits within 2 s whatever is rendering"): a client streams
# 2048² frames; once the server has sent one, SIGTERM; the server must exit 0
# within 2 s (the frame in progress is cancelled at its next tile, the
# session is told SHUTTING_DOWN and closed).
#
# usage: sigterm_during_frame.sh HAARCAST HAARCAST_CLIENT
set -uo pipefail
server_bin="${1:?usage: sigterm_during_frame.sh HAARCAST HAARCAST_CLIENT}"
client_bin="${2:?usage: sigterm_during_frame.sh HAARCAST HAARCAST_CLIENT}"
limit_s=2
work="$(mktemp -d -t haarcast-sigterm.XXXXXX)"
server_pid="" client_pid=""
cleanup() {
  [[ -n "$client_pid" ]] && { kill -KILL "$client_pid"; wait "$client_pid"; } 2>/dev/null
  [[ -n "$server_pid" ]] && { kill -KILL "$server_pid"; wait "$server_pid"; } 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT

source "$(dirname "${BASH_SOURCE[0]}")/start_server.sh"
start_server "$server_bin" serve --port 0 --backend cpu --level 4

"$client_bin" "ws://127.0.0.1:$port" --size 2048x2048 --frames 1000 --orbit 360 --quiet --timeout 300 \
  >"$work/client.out" 2>"$work/client.err" &
client_pid=$!
# The first frame sent: from then on a 2048² frame is always rendering.
for ((i = 0; i < 1200; i++)); do
  frames="$(curl -s "http://127.0.0.1:$port/metrics" | sed -n 's/^haarcast_frames_total \([0-9]*\)$/\1/p')"
  [[ "${frames:-0}" -ge 1 ]] && break
  sleep 0.1
done
[[ "${frames:-0}" -ge 1 ]] || { echo "FAIL: no 2048² frame within 120 s"; tail -5 "$work/server.err"; exit 1; }
sleep 0.3  # into the next frame

start=$(date +%s.%N)
kill -TERM "$server_pid"
rc=124
for ((i = 0; i < 100; i++)); do
  if ! kill -0 "$server_pid" 2>/dev/null; then
    wait "$server_pid"
    rc=$?
    break
  fi
  sleep 0.05
done
elapsed=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.2f}')" "$start" "$(date +%s.%N)")
server_pid=""
echo "SIGTERM during a 2048² frame: exit $rc after $elapsed s (limit $limit_s s)"
in_time=$(python3 -c "import sys; print(int(float(sys.argv[1]) < float(sys.argv[2])))" "$elapsed" "$limit_s")
if [[ "$rc" != 0 || "$in_time" != 1 ]]; then
  echo "FAIL"
  tail -5 "$work/server.err"
  exit 1
fi
echo "passed"
