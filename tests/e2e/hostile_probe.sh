#!/usr/bin/env bash
# The hostile-client probe of docs/hardening.md, rerun against the binary
# with its default limits: DNS rebinding (a foreign Host with a matching
# Origin), 8 addresses of silent upgrades filling the pre-Hello budget, a
# token spray from 200 addresses (and the log it writes), unknown transfer
# codings, a FIFO given as each kind of input file, and corrupt cache files.
# With the client binary too, the gRPC port (grpc_probe.py): rapid reset for
# $HAARCAST_PROBE_GRPC_SECONDS (default 5; 60 for the figures in
# docs/hardening.md) beside honest gRPC and WebSocket clients, 100 addresses
# × 8 silent streams, a token spray, and a frame that never returns.
# Prints one line of figures per attack; exits 1 at the first one not held.
# 127.0.0.x are distinct client addresses on Linux loopback.
#
# usage: hostile_probe.sh HAARCAST_BINARY [HAARCAST_CLIENT]
set -euo pipefail
haarcast="${1:?usage: hostile_probe.sh HAARCAST_BINARY [HAARCAST_CLIENT]}"
client="${2:-}"
work="$(mktemp -d -t haarcast-hostile.XXXXXX)"
server_pid=""
cleanup() {
  [[ -n "$server_pid" ]] && kill -KILL "$server_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
source "$(dirname "${BASH_SOURCE[0]}")/start_server.sh"

fail() {
  echo "FAIL: $*"
  echo "--- server log:"
  tail -n 20 "$work/server.err" 2>/dev/null || true
  exit 1
}
stop_server() {
  kill -TERM "$server_pid"
  wait "$server_pid" || true
  server_pid=""
  # The next start_server must not read this one's port.
  rm -f "$work/server.out" "$work/server.err"
}

# ---- the default bind, no token: Host, pre-Hello budget, Transfer-Encoding
start_server "$haarcast" serve --port 0 --backend cpu --cache-dir none --allow-host render.example
python3 - "$port" <<'PY' || fail "the probe above"
import socket, sys, time
port = int(sys.argv[1])

def request(text, source="127.0.0.1", keep=False):
    s = socket.create_connection(("127.0.0.1", port), timeout=5, source_address=(source, 0))
    s.sendall(text.encode())
    head = b""
    while b"\r\n\r\n" not in head:
        chunk = s.recv(4096)
        if not chunk:
            break
        head += chunk
    status = int(head.split(b" ", 2)[1]) if head else 0
    if keep:
        return status, s
    s.close()
    return status

def upgrade(host, origin="", source="127.0.0.1", keep=False):
    extra = f"Origin: {origin}\r\n" if origin else ""
    return request(f"GET /ws HTTP/1.1\r\nHost: {host}\r\n{extra}Upgrade: websocket\r\nConnection: Upgrade\r\n"
                   "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n", source, keep)

def get(path, host="127.0.0.1"):
    return request(f"GET {path} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n")

def metric(name):
    s = socket.create_connection(("127.0.0.1", port), timeout=5)
    s.sendall(b"GET /metrics HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n")
    data = b""
    while chunk := s.recv(65536):
        data += chunk
    for line in data.decode().splitlines():
        if line.startswith(name + " "):
            return float(line.split()[1])
    return -1

def check(ok, what):
    if not ok:
        print("FAIL:", what)
        sys.exit(1)

evil = f"evil.example:{port}"
statuses = (upgrade(evil, f"http://{evil}"), get("/metrics", evil), get("/healthz", evil))
check(statuses == (421, 421, 200), f"rebinding: /ws, /metrics, /healthz got {statuses}")
allowed = upgrade(f"render.example:{port}", f"http://render.example:{port}")
check(allowed == 101, f"the allowed name got {allowed}")
print(f"rebinding: Host {evil} + matching Origin → /ws 421, /metrics 421, /healthz 200; --allow-host name → 101")

silent = []
for a in range(8):
    for _ in range(8):
        status, s = upgrade("127.0.0.1", source=f"127.0.0.{a + 2}", keep=True)
        check(status == 101, f"silent upgrade {a} got {status}")
        silent.append(s)
pending = metric("haarcast_pending_connections")
ready = get("/readyz")
ninth, s9 = upgrade("127.0.0.1", source="127.0.0.100", keep=True)
check(ninth == 101, f"a ninth address got {ninth} with the pre-Hello budget full")
silent[0].settimeout(3)
try:
    evicted = silent[0].recv(1) == b""
except OSError:
    evicted = True
check(evicted, "the oldest silent upgrade was not closed")
evictions = metric('haarcast_session_cuts_total{reason="pending_evicted"}')
print(f"pre-Hello budget: 8 addresses x 8 silent upgrades → pending {pending:.0f}, /readyz {ready}; "
      f"a 9th address → {ninth}, the oldest silent one closed (pending_evicted {evictions:.0f})")

codings = [request(f"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: {c}\r\n\r\n")
           for c in ("xchunked", "chunked, identity")]
check(codings == [400, 400], f"Transfer-Encoding xchunked / chunked, identity got {codings}")
print("Transfer-Encoding: xchunked → 400, chunked, identity → 400")
PY
stop_server

# ---- a token: a spray of wrong tokens from 200 addresses, and its log
start_server "$haarcast" serve --port 0 --backend cpu --cache-dir none --token s3cret
log_before=$(wc -c <"$work/server.err")
python3 - "$port" <<'PY' || fail "the token spray"
import socket, sys, time
port = int(sys.argv[1])
def upgrade(token, source):
    s = socket.create_connection(("127.0.0.1", port), timeout=5, source_address=(source, 0))
    s.sendall((f"GET /ws?token={token} HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
               "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n").encode())
    head = s.recv(4096)
    s.close()
    return int(head.split(b" ", 2)[1])
known = upgrade("s3cret", "127.0.0.1")
t0 = time.monotonic()
counts = {}
for i in range(1000):
    status = upgrade(f"guess{i}", f"127.0.0.{i % 200 + 2}")
    counts[status] = counts.get(status, 0) + 1
seconds = time.monotonic() - t0
after = upgrade("s3cret", "127.0.0.1")
stranger = upgrade("s3cret", "127.0.0.250")
print(f"token spray: 1000 guesses from 200 addresses in {seconds:.2f} s → {counts.get(401, 0)} x 401, "
      f"{counts.get(429, 0)} x 429; the known client then {after}, a new address {stranger}")
sys.exit(0 if counts.get(401, 0) == 100 and counts.get(429, 0) == 900 and known == after == 101 and stranger == 429 else 1)
PY
sleep 0.2
log_bytes=$(( $(wc -c <"$work/server.err") - log_before ))
log_lines=$(tail -c "$log_bytes" "$work/server.err" | grep -c refused || true)
echo "token spray log: $log_lines refusal lines, $log_bytes bytes"
(( log_lines <= 201 )) || fail "$log_lines refusal lines for 200 addresses"
stop_server

# ---- a FIFO as each kind of input file
mkfifo "$work/probe.hdr" "$work/mesh.ply" "$work/brdf.binary" "$work/scene.json"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$work/tri.obj"
for args in "--mesh $work/tri.obj --env $work/probe.hdr" "--mesh $work/mesh.ply" \
            "--mesh $work/tri.obj --material $work/brdf.binary" "--scene $work/scene.json"; do
  start=$(date +%s.%N)
  # shellcheck disable=SC2086
  if timeout 10 "$haarcast" render $args --out "$work/x.png" --width 8 --height 8 >"$work/fifo.out" 2>&1; then
    fail "render $args succeeded"
  fi
  took=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.2f}')" "$start" "$(date +%s.%N)")
  grep -q "is a FIFO (named pipe), not a regular file" "$work/fifo.out" || { cat "$work/fifo.out"; fail "render $args: no FIFO error"; }
  echo "FIFO: render ${args##*/} → exit in $took s: $(grep -m1 -o 'is a FIFO.*' "$work/fifo.out")"
done

# ---- corrupt cache files: rebuilt and logged once each, with their names
# (haarcast_cache_rebuilds_total counts them in a server: CacheRebuilds.* and
# the metrics test)
"$haarcast" render --cache-dir "$work/cache" --level 2 --width 8 --height 8 --out "$work/a.png" >/dev/null 2>&1 ||
  fail "a render to fill the cache"
files=("$work"/cache/*.hccache)
[[ -e "${files[0]}" ]] || fail "no cache file written"
for f in "${files[@]}"; do
  python3 - "$f" <<'PY'
import sys
path = sys.argv[1]
data = bytearray(open(path, "rb").read())
data[len(data) - 9] ^= 0x40  # the last payload byte: the checksum no longer matches
open(path, "wb").write(data)
PY
done
"$haarcast" render --cache-dir "$work/cache" --level 2 --width 8 --height 8 --out "$work/b.png" >/dev/null \
  2>"$work/render.err" || fail "a render over corrupt cache files"
logged=$(grep -c "is corrupt" "$work/render.err" || true)
named=$(grep -c "cache file $work/cache/.*hccache is corrupt" "$work/render.err" || true)
echo "corrupt cache: ${#files[@]} files → rebuilt, $logged log lines naming them ($(grep -m1 'is corrupt' "$work/render.err"))"
[[ "$logged" == "${#files[@]}" && "$named" == "$logged" ]] || fail "corrupt cache files: $logged logged for ${#files[@]}"

# ---- the gRPC port (Debian's python3 has grpcio: python3-grpcio)
if [[ -n "$client" ]]; then
  rc=0
  /usr/bin/python3 "$(dirname "${BASH_SOURCE[0]}")/grpc_probe.py" --haarcast "$haarcast" --client "$client" \
    --seconds "${HAARCAST_PROBE_GRPC_SECONDS:-5}" || rc=$?
  if ((rc == 77)); then
    echo "gRPC: skipped (no grpc module in /usr/bin/python3)"
  elif ((rc != 0)); then
    exit 1
  fi
fi
echo "PASS"
