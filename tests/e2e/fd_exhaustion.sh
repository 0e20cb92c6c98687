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

# The gRPC port through the same exhaustion. gRPC 1.51 stops accepting on a
# port for good after accept() failed with EMFILE (CVE-2023-4785): within
# 12 s of the descriptors coming back, the port either answers an HTTP/2
# preface again or /healthz answers 503 naming it (the server's own probe,
# listener_probe.h), so that an orchestrator restarts it. Never a dead port
# behind a 200.
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
sleep 3
touch "$work/release"
wait "$holder_pid" || true
holder_pid=""
verdict=""
released=$SECONDS
while ((SECONDS - released < 12)); do
  if http2_answers; then verdict="the gRPC port accepts again"; break; fi
  code="$(python3 - "$port" "$work/healthz.txt" <<'PY'
import sys, urllib.request, urllib.error
try:
    with urllib.request.urlopen(f"http://127.0.0.1:{sys.argv[1]}/healthz", timeout=2) as r:
        code, body = r.status, r.read()
except urllib.error.HTTPError as e:
    code, body = e.code, e.read()
except Exception:
    code, body = 0, b""
open(sys.argv[2], "wb").write(body)
print(code)
PY
)"
  if [[ "$code" == 503 ]] && grep -q "gRPC port $grpc_port" "$work/healthz.txt"; then
    verdict="/healthz 503: $(cat "$work/healthz.txt")"
    break
  fi
  sleep 0.1
done
[[ -n "$verdict" ]] || fail "12 s after the gRPC flood the port does not answer and /healthz says $(cat "$work/healthz.txt" 2>/dev/null)"
echo "after the gRPC flood: $verdict (within $((SECONDS - released)) s)"
kill -TERM "$server_pid"
rc=0
wait "$server_pid" || rc=$?
server_pid=""
((rc == 0)) || fail "the server exited $rc on SIGTERM after the gRPC flood"
echo "PASS"
