#!/usr/bin/env bash
# Soak test: N clients for T seconds against one server, then the figures an
# operator needs to trust it under long load.
#
#   deploy/soak.sh [--clients N] [--seconds T] [--size WxH] [--encoding E]
#                  [--url ws://HOST:PORT --pid PID] [-- extra `serve` args]
#
# Without --url it starts `haarcast serve --port 0` (CPU backend unless the
# extra args say otherwise) and stops it with SIGTERM at the end; with --url
# it drives a running server, and --pid names that server's process so its
# RSS can be read (else RSS is reported as unknown).
#
# Prints, and writes as JSON to $SOAK_OUT/soak.json when SOAK_OUT is set:
#   frames per client (min, median, max), errors, pose → frame latency p50/p99,
#   server RSS at start and end (/proc/PID/status VmRSS) and its growth,
#   and whether the server exited 0 on SIGTERM.
# Exit status 1 when a client failed, an Error arrived, a client got no frame,
# or the server did not exit cleanly. Environment: BUILD_DIR (default build),
# HAARCAST_TOKEN (passed to server and clients).
set -euo pipefail
BUILD_DIR="${BUILD_DIR:-build}"
clients=16 seconds=600 size=128x128 encoding=jpeg url="" pid=""
serve_args=()
while (($# > 0)); do
  case "$1" in
    --clients) clients="${2:?}"; shift 2 ;;
    --seconds) seconds="${2:?}"; shift 2 ;;
    --size) size="${2:?}"; shift 2 ;;
    --encoding) encoding="${2:?}"; shift 2 ;;
    --url) url="${2:?}"; shift 2 ;;
    --pid) pid="${2:?}"; shift 2 ;;
    --) shift; serve_args=("$@"); break ;;
    -h | --help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0" >&2; exit 2 ;;
    *) echo "soak: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ "$clients" =~ ^[0-9]+$ && "$clients" -ge 1 ]] || { echo "soak: --clients needs a whole number ≥ 1" >&2; exit 2; }
[[ "$seconds" =~ ^[0-9]+$ && "$seconds" -ge 1 ]] || { echo "soak: --seconds needs a whole number ≥ 1" >&2; exit 2; }
server_bin="$BUILD_DIR/bin/haarcast" client_bin="$BUILD_DIR/bin/haarcast-client"
[[ -x "$client_bin" ]] || { echo "soak: no $client_bin (deploy/run.sh build)" >&2; exit 1; }
token="${HAARCAST_TOKEN:-}"
work="$(mktemp -d -t haarcast-soak.XXXXXX)"
started=""
cleanup() {
  [[ -n "$started" ]] && kill -0 "$pid" 2>/dev/null && kill -KILL "$pid" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT

rss_kib() { [[ -n "$pid" && -r "/proc/$pid/status" ]] && awk '/^VmRSS:/ { print $2 }' "/proc/$pid/status" || echo ""; }

if [[ -z "$url" ]]; then
  [[ -x "$server_bin" ]] || { echo "soak: no $server_bin (deploy/run.sh build)" >&2; exit 1; }
  # Every client comes from 127.0.0.1: no session slots are kept for new
  # addresses (--session-reserve 0), as behind an ingress.
  args=(serve --port 0 --backend cpu --max-sessions "$clients" --max-sessions-per-address "$clients"
        --max-connections-per-address "$((clients * 2))" --max-pending-per-address "$clients" --session-reserve 0
        "${serve_args[@]}")
  [[ -n "$token" ]] && args+=(--token "$token")
  echo "soak: starting $server_bin ${args[*]}"
  "$server_bin" "${args[@]}" >"$work/server.out" 2>"$work/server.err" </dev/null &
  pid=$! started=1
  port=""
  for ((i = 0; i < 600; i++)); do
    # (the file may not exist yet: the server's redirect races this loop)
    port="$(sed -n 's#.*listening on http://[^:]*:\([0-9]*\)/.*#\1#p' "$work/server.out" 2>/dev/null | head -1 || true)"
    [[ -n "$port" ]] && break
    kill -0 "$pid" 2>/dev/null || { cat "$work/server.err" >&2; echo "soak: the server exited before listening" >&2; exit 1; }
    sleep 0.1
  done
  [[ -n "$port" ]] || { echo "soak: no 'listening on' line in 60 s" >&2; exit 1; }
  url="ws://127.0.0.1:$port"
fi

# A short warm-up session builds the renderer, so the start RSS is the
# server's steady state and not its empty start.
warm=("$url" --frames 3 --size "$size" --encoding "$encoding" --quiet --timeout 300)
[[ -n "$token" ]] && warm+=(--token "$token")
"$client_bin" "${warm[@]}" >/dev/null 2>"$work/warm.err" || { cat "$work/warm.err" >&2; echo "soak: the warm-up session failed" >&2; exit 1; }
rss_start="$(rss_kib)"
echo "soak: $clients clients × $seconds s at $size ($encoding) against $url; server RSS ${rss_start:-unknown} KiB"

run=("$url" --clients "$clients" --duration "$seconds" --size "$size" --encoding "$encoding"
     --orbit 90 --light 45 --json --quiet --timeout 120)
[[ -n "$token" ]] && run+=(--token "$token")
client_rc=0
"$client_bin" "${run[@]}" >"$work/summary.json" 2>"$work/client.err" || client_rc=$?
rss_end="$(rss_kib)"

server_rc=""
if [[ -n "$started" ]]; then
  kill -TERM "$pid"
  t0=$EPOCHREALTIME
  server_rc=0
  wait "$pid" || server_rc=$?
  stop_seconds="$(python3 -c "print($EPOCHREALTIME - $t0)")"
  started=""
fi

python3 - "$work/summary.json" "$client_rc" "${rss_start:-}" "${rss_end:-}" "${server_rc:-}" "${stop_seconds:-}" <<'PY'
import json, os, statistics, sys
path, client_rc, rss0, rss1, server_rc, stop_s = sys.argv[1:7]
try:
    s = json.load(open(path))
except Exception as e:
    print(f"soak: FAIL: no client summary ({e})", file=sys.stderr); sys.exit(1)
per = s.get("per_client", [])
frames = [c.get("frames", 0) for c in per]
out = {
    "clients": len(per),
    "frames_per_client": {"min": min(frames, default=0), "median": statistics.median(frames) if frames else 0,
                          "max": max(frames, default=0)},
    "errors": s.get("errors", 0),
    "latency_ms": {"p50": s.get("latency_ms_p50"), "p99": s.get("latency_ms_p99")},
    "fps_total": s.get("fps"),
    "server_rss_kib": {"start": int(rss0) if rss0 else None, "end": int(rss1) if rss1 else None},
    "server_exit": int(server_rc) if server_rc else None,
    "server_stop_seconds": float(stop_s) if stop_s else None,
    "client_exit": int(client_rc),
}
r = out["server_rss_kib"]
out["server_rss_growth_percent"] = (100.0 * (r["end"] - r["start"]) / r["start"]) if r["start"] and r["end"] else None
f = out["frames_per_client"]
print(f"soak: frames per client min {f['min']} / median {f['median']} / max {f['max']}; errors {out['errors']}; "
      f"latency p50 {out['latency_ms']['p50']:.1f} ms, p99 {out['latency_ms']['p99']:.1f} ms")
if out["server_rss_growth_percent"] is not None:
    print(f"soak: server RSS {r['start']} → {r['end']} KiB ({out['server_rss_growth_percent']:+.2f} %)")
if out["server_exit"] is not None:
    print(f"soak: server exit {out['server_exit']} after SIGTERM in {out['server_stop_seconds']:.2f} s")
if os.environ.get("SOAK_OUT"):
    os.makedirs(os.environ["SOAK_OUT"], exist_ok=True)
    json.dump(out, open(os.path.join(os.environ["SOAK_OUT"], "soak.json"), "w"), indent=2)
bad = []
if out["client_exit"] != 0: bad.append(f"the client run exited {out['client_exit']}")
if out["errors"]: bad.append(f"{out['errors']} Error messages")
if f["min"] == 0: bad.append("a client got no frame")
if out["server_exit"] not in (None, 0): bad.append(f"the server exited {out['server_exit']} on SIGTERM")
if bad:
    print("soak: FAIL: " + "; ".join(bad), file=sys.stderr); sys.exit(1)
PY
