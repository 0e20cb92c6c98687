#!/usr/bin/env bash
# Descriptor exhaustion at accept. A server limited to 64 open files is sent
# more connections than it can hold, all kept open. While accept fails with
# EMFILE it must pause (not retry at once: that spun a core and logged 153 MB
# in 20 s) and log one line for the episode; once the connections go, it must
# accept again and answer /healthz. Then the same against the gRPC port.
#
# usage: fd_exhaustion.sh HAARCAST_BINARY
set -euo pipefail
haarcast="${1:?usage: fd_exhaustion.sh HAARCAST_BINARY}"
work="$(mktemp -d -t haarcast-fd.XXXXXX)"
server_pid=""
holder_pid=""
cleanup() {
  [[ -n "$holder_pid" ]] && kill "$holder_pid" 2>/dev/null || true
  [[ -n "$server_pid" ]] && kill -KILL "$server_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
source "$(dirname "${BASH_SOURCE[0]}")/start_server.sh"

fail() {
  echo "FAIL: $*"
  echo "--- server log:"
  tail -n 20 "$work/server.err"
  exit 1
}
cpu_ticks() { awk '{ print $14 + $15 }' "/proc/$server_pid/stat"; }
healthz() {
  python3 - "$port" <<'PY'
import sys, urllib.request
try:
    with urllib.request.urlopen(f"http://127.0.0.1:{sys.argv[1]}/healthz", timeout=2) as r:
        sys.exit(0 if r.status == 200 else 1)
except Exception:
    sys.exit(1)
PY
}

# 150 connections to port $1 that send nothing and stay open until
# $work/release exists; returns once they are all made.
hold_connections() {
  python3 - "$1" "$work/holding" "$work/release" <<'PY' &
import os, socket, sys, time
port, holding, release = int(sys.argv[1]), sys.argv[2], sys.argv[3]
held = [socket.create_connection(("127.0.0.1", port), timeout=5) for _ in range(150)]
open(holding, "w").close()
while not os.path.exists(release):
    time.sleep(0.05)
for s in held:
    s.close()
PY
  holder_pid=$!
  for ((i = 0; i < 200; i++)); do [[ -e "$work/holding" ]] && break; sleep 0.05; done
  [[ -e "$work/holding" ]] || fail "the 150 connections to port $1 were not all made"
}

# The per-address cap would close the flood at accept before descriptors ran
# out; lift it so exhaustion is what is tested. A 30 s request timeout keeps
# the idle connections open for the whole measurement.
start_server prlimit --nofile=64:64 "$haarcast" serve --port 0 --backend cpu --cache-dir none \
  --max-connections-per-address 10000 --handshake-timeout 30
healthz || fail "/healthz before the flood"

hold_connections "$port"

# Exhausted for 3 s: the server must be paused, not spinning on accept.
for ((i = 0; i < 100; i++)); do grep -q "pausing accepts" "$work/server.err" && break; sleep 0.1; done
grep -q "pausing accepts" "$work/server.err" || fail "no 'pausing accepts' line within 10 s of the flood"
ticks0="$(cpu_ticks)"
sleep 3
ticks1="$(cpu_ticks)"
hz="$(getconf CLK_TCK)"
used="$(python3 -c "print(($ticks1 - $ticks0) / $hz)")"
echo "server CPU over 3 s with descriptors exhausted: $used s"
python3 -c "import sys; sys.exit(0 if $used < 0.6 else 1)" || fail "the server used $used s of CPU in 3 s: the accept loop spins"
lines="$(grep -c "^.*accept:" "$work/server.err" || true)"
echo "accept log lines during the episode: $lines"
((lines <= 2)) || fail "$lines accept lines: the log grows with every failed accept"

# The connections go: accepts resume and the server answers again.
touch "$work/release"
wait "$holder_pid" || true
holder_pid=""
ok=""
for ((i = 0; i < 100; i++)); do
  if healthz; then ok=1; break; fi
  sleep 0.1
done
[[ -n "$ok" ]] || fail "/healthz did not answer within 10 s after the connections closed"
for ((i = 0; i < 50; i++)); do grep -q "accept: recovered after" "$work/server.err" && break; sleep 0.1; done
grep -q "accept: recovered after" "$work/server.err" || fail "no 'recovered' line after the episode"
grep "accept:" "$work/server.err"

kill -TERM "$server_pid"
rc=0
wait "$server_pid" || rc=$?
server_pid=""
((rc == 0)) || fail "the server exited $rc on SIGTERM"
rm -f "$work/holding" "$work/release" "$work/server.out" "$work/server.err"

# The gRPC port through the same exhaustion. Its connections are accepted by
# the server's own loop (grpc_front.h), not by gRPC 1.51, whose listener
# stopped for good after accept() failed with EMFILE (CVE-2023-4785): the
# loop pauses as the WebSocket port's does, and within 5 s of the
# descriptors coming back both ports answer again and /healthz says 200.
# --grpc-port 0 is no gRPC: a port free a moment ago.
grpc_port="$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')"
start_server prlimit --nofile=64:64 "$haarcast" serve --port 0 --grpc-port "$grpc_port" --backend cpu --cache-dir none \
  --max-connections-per-address 10000 --handshake-timeout 30
http2_answers() {
  python3 - "$grpc_port" <<'PY'
import socket, sys
try:
    s = socket.create_connection(("127.0.0.1", int(sys.argv[1])), timeout=0.5)
    s.sendall(b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n" + bytes(9)[:3] + b"\x04" + bytes(5))
    header = s.recv(9)
    sys.exit(0 if len(header) >= 4 and header[3] == 4 else 1)
except Exception:
    sys.exit(1)
PY
}
http2_answers || fail "the gRPC port does not answer before the flood"
healthz || fail "/healthz before the gRPC flood"
hold_connections "$grpc_port"
for ((i = 0; i < 100; i++)); do grep -q "gRPC accept: .*pausing accepts" "$work/server.err" && break; sleep 0.1; done
grep -q "gRPC accept: .*pausing accepts" "$work/server.err" || fail "no 'gRPC accept: … pausing accepts' line within 10 s of the gRPC flood"
sleep 2
touch "$work/release"
wait "$holder_pid" || true
holder_pid=""
released=$SECONDS
answered=""
while ((SECONDS - released < 12)); do
  if http2_answers && healthz; then answered=$((SECONDS - released)); break; fi
  sleep 0.1
done
[[ -n "$answered" ]] || fail "12 s after the gRPC flood the gRPC port or /healthz does not answer"
echo "after the gRPC flood: the gRPC port answers HTTP/2 and /healthz 200 within $answered s"
((answered <= 5)) || fail "the ports answered only $answered s after the descriptors came back (target: 5 s)"
for ((i = 0; i < 50; i++)); do grep -q "gRPC accept: recovered after" "$work/server.err" && break; sleep 0.1; done
grep -q "gRPC accept: recovered after" "$work/server.err" || fail "no 'gRPC accept: recovered' line after the gRPC flood"
grep "gRPC accept:" "$work/server.err"
kill -TERM "$server_pid"
rc=0
wait "$server_pid" || rc=$?
server_pid=""
((rc == 0)) || fail "the server exited $rc on SIGTERM after the gRPC flood"
echo "PASS"
