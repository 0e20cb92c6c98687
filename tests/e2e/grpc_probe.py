#!/usr/bin/env python3
"""The hostile-client probe of the gRPC port (docs/hardening.md), against
`haarcast serve --grpc-port` on loopback with a token. 127.0.0.x are distinct
client addresses on Linux loopback. In turn:

  rapid reset   HEADERS then RST_STREAM on stream after stream from one
                address, reconnecting whenever cut, for --seconds, while an
                honest gRPC client (grpcio) and an honest WebSocket client
                (haarcast-client) render; their frame rates are measured
                before and during, the server's RSS every second, and SIGTERM
                is sent while the attack still runs.
  silent        100 addresses × 8 gRPC streams that never send a message:
                the server's live pending count against --max-pending.
  spray         1,000 wrong tokens from 200 addresses on gRPC streams; a
                client that showed the right token before is still served.
  stuck         a frame that never returns (HAARCAST_TEST_STALL_STAGE, the
                test-only fault of docs/service.md) with --frame-deadline 1:
                the gRPC client gets an Error naming the stage, gRPC health
                says NOT_SERVING and /readyz 503, SIGTERM ends it within 2 s.

Prints a line of figures per attack and exits 1 at the first target missed.
The targets: RSS under 300 MB at every second, honest clients keep >= 50 % of
their frame rate, SIGTERM within 2 s, pending <= --max-pending, the known
client served, the stuck frame reported.

usage: grpc_probe.py --haarcast BIN --client BIN [--seconds N]
Exit 77 (skip) when Debian's /usr/bin/python3 lacks grpc (python3-grpcio).
"""
import argparse
import json
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request

SKIP = 77
TOKEN = "probe-token"
PREFACE = b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n"

try:
    import grpc
except ImportError:
    print("skip: no grpc module in this python3 (apt-get install python3-grpcio)")
    sys.exit(SKIP)


def fail(what):
    print(f"FAIL: {what}", flush=True)
    sys.exit(1)


# ---------------------------------------------------------------- protobuf by hand
def varint(n):
    out = bytearray()
    while True:
        b = n & 0x7F
        n >>= 7
        out.append(b | (0x80 if n else 0))
        if not n:
            return bytes(out)


def field(number, payload):
    """A length-delimited field."""
    return varint(number << 3 | 2) + varint(len(payload)) + payload


def uint_field(number, value):
    return varint(number << 3) + varint(value)


def double_field(number, value):
    import struct
    return varint(number << 3 | 1) + struct.pack("<d", value)


def hello(token, width=64, height=64):
    body = uint_field(1, 1) + field(2, token.encode()) + uint_field(3, width) + uint_field(4, height)
    body += uint_field(5, 1) + field(8, b"grpc-probe")  # JPEG
    return field(1, body)  # ClientMessage.hello


def pose(sequence):
    # An object turned a little more each time: every pose is a new picture.
    vec = double_field(2, float(sequence % 360))  # Vec3.y
    obj = uint_field(1, 0) + field(2, vec)
    return field(2, uint_field(1, sequence) + field(3, obj))  # ClientMessage.pose


def body_case(message):
    """The ServerMessage's oneof field number."""
    return message[0] >> 3 if message else 0


# ---------------------------------------------------------------- raw HTTP/2
def frame(ftype, flags, stream, payload=b""):
    n = len(payload)
    return bytes([(n >> 16) & 0xFF, (n >> 8) & 0xFF, n & 0xFF, ftype, flags]) + stream.to_bytes(4, "big") + payload


def session_headers(stream, authorization):
    """HEADERS for a call to Render/Session: HPACK literals, no Huffman."""
    def literal(index, value):
        return bytes([index, len(value)]) + value

    block = b"\x83\x86"  # :method POST, :scheme http
    block += literal(0x04, b"/haarcast.v1.Render/Session")
    block += literal(0x01, b"localhost")
    block += b"\x0f\x10" + bytes([16]) + b"application/grpc"
    block += b"\x00" + bytes([2]) + b"te" + bytes([8]) + b"trailers"
    if authorization:
        value = authorization.encode()
        block += b"\x00" + bytes([13]) + b"authorization" + bytes([len(value)]) + value
    return frame(0x1, 0x4, stream, block)


def reset(stream):
    return frame(0x3, 0, stream, b"\x00\x00\x00\x08")


def raw_connect(port, source):
    s = socket.socket()
    s.bind((source, 0))
    s.settimeout(5)
    s.connect(("127.0.0.1", port))
    s.sendall(PREFACE + frame(0x4, 0, 0))
    return s


# ---------------------------------------------------------------- the server
def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def rss_mb(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return 0.0


def metric(port, name):
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/metrics", timeout=5) as r:
        text = r.read().decode()
    m = re.search(r"^" + re.escape(name) + r" (\S+)$", text, re.M)
    return float(m.group(1)) if m else 0.0


class Honest(threading.Thread):
    """A gRPC client that sends a new pose for each frame; counts frames."""

    def __init__(self, port):
        super().__init__(daemon=True)
        self.frames = []
        self.error = None
        self.stop = threading.Event()
        self.next_pose = threading.Event()
        self.channel = grpc.insecure_channel(f"127.0.0.1:{port}")
        self.call = self.channel.stream_stream("/haarcast.v1.Render/Session", request_serializer=None,
                                               response_deserializer=None)

    def requests(self):
        yield hello(TOKEN)
        sequence = 0
        while not self.stop.is_set():
            if self.next_pose.wait(0.2):
                self.next_pose.clear()
                sequence += 1
                yield pose(sequence)

    def run(self):
        try:
            for message in self.call(self.requests(), metadata=[("authorization", f"Bearer {TOKEN}")], timeout=600):
                if body_case(message) == 2:  # Frame
                    self.frames.append(time.monotonic())
                    self.next_pose.set()
                elif body_case(message) == 4 and self.error is None:
                    self.error = "Error: " + re.sub(r"[^\x20-\x7e]+", " ", message.decode("utf-8", "replace")).strip()
                if self.stop.is_set():
                    break
        except grpc.RpcError as e:
            if not self.stop.is_set() and self.error is None:
                self.error = f"{e.code()}: {e.details()}"

    def wait_frames(self, n, limit):
        """True once `n` frames have come, within `limit` seconds (the first
        waits for the session's renderer: a build, slower on a busy machine)."""
        end = time.monotonic() + limit
        while len(self.frames) < n and self.error is None and time.monotonic() < end:
            time.sleep(0.05)
        return len(self.frames) >= n

    def fps(self, since, until):
        return sum(1 for t in self.frames if since <= t < until) / (until - since)


def ws_fps(client, port, seconds):
    """haarcast-client on the WebSocket port for `seconds`: frames a second."""
    out = subprocess.run([client, f"ws://127.0.0.1:{port}/ws", "--token", TOKEN, "--size", "64x64", "-n", "100000",
                          "--duration", str(seconds), "--json"], capture_output=True, text=True, timeout=seconds + 60)
    if out.returncode != 0:
        return 0.0, out.stderr.strip().splitlines()[-1:] or ["?"]
    summary = json.loads(out.stdout)
    return float(summary["per_client"][0]["fps"] or 0.0), []


def health(port):
    """grpc.health.v1.Health/Check for "": 1 SERVING, 2 NOT_SERVING, -1 failed."""
    channel = grpc.insecure_channel(f"127.0.0.1:{port}")
    try:
        answer = channel.unary_unary("/grpc.health.v1.Health/Check", request_serializer=None,
                                     response_deserializer=None)(b"", timeout=5)
    except grpc.RpcError:
        return -1
    finally:
        channel.close()
    return answer[1] if len(answer) >= 2 and answer[0] == 0x08 else 0


def start(haarcast, extra=(), env=None):
    port, grpc_port = free_port(), free_port()
    log = tempfile.TemporaryFile()
    server = subprocess.Popen([haarcast, "serve", "--port", str(port), "--grpc-port", str(grpc_port), "--token", TOKEN,
                               "--backend", "cpu", "--cache-dir", "none", *extra],
                              stdout=subprocess.DEVNULL, stderr=log, env=env)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/readyz", timeout=2) as r:
                if r.status == 200:
                    return server, port, grpc_port, log
        except Exception:
            time.sleep(0.2)
    server.kill()
    fail("the server was not ready within 120 s")


def stop(server, limit=10):
    """SIGTERM; (status or None, seconds to exit)."""
    t = time.monotonic()
    server.send_signal(signal.SIGTERM)
    try:
        rc = server.wait(limit)
    except subprocess.TimeoutExpired:
        server.kill()
        server.wait()
        rc = None
    return rc, time.monotonic() - t


def rapid_reset(port, source, halt, counts):
    """HEADERS + RST_STREAM as fast as the socket takes them; reconnects."""
    while not halt.is_set():
        try:
            s = raw_connect(port, source)
        except OSError:
            counts["refused"] += 1
            time.sleep(0.01)
            continue
        counts["connections"] += 1
        stream = 1
        try:
            while not halt.is_set():
                batch = b"".join(session_headers(stream + 2 * i, f"Bearer {TOKEN}") + reset(stream + 2 * i)
                                 for i in range(50))
                s.sendall(batch)
                stream += 100
                counts["streams"] += 50
        except OSError:
            pass
        s.close()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--haarcast", required=True)
    ap.add_argument("--client", required=True)
    ap.add_argument("--seconds", type=float, default=60)
    ap.add_argument("--max-pending", type=int, default=64)
    args = ap.parse_args()

    server, port, grpc_port, log = start(args.haarcast, ["--max-pending", str(args.max_pending)])
    try:
        # ---- rapid reset
        honest = Honest(grpc_port)
        honest.start()
        if not honest.wait_frames(3, 120):  # its renderer built, its frames flowing
            fail(f"the honest gRPC client got no frames within 120 s ({honest.error})")
        measure = max(3.0, min(10.0, args.seconds / 3))
        t0 = time.monotonic()
        ws_before, problem = ws_fps(args.client, port, measure)
        t1 = time.monotonic()
        grpc_before = honest.fps(t0, t1)
        if problem or grpc_before == 0:
            fail(f"honest clients before the attack: WebSocket {ws_before:.1f} fps {problem}, gRPC {grpc_before:.1f} fps "
                 f"{honest.error or ''}")
        halt = threading.Event()
        counts = {"connections": 0, "refused": 0, "streams": 0}
        attacker = threading.Thread(target=rapid_reset, args=(grpc_port, "127.0.0.9", halt, counts), daemon=True)
        rss = []
        attacker.start()
        a0 = time.monotonic()
        ws_result = {}
        ws_thread = threading.Thread(target=lambda: ws_result.update(r=ws_fps(args.client, port, measure)), daemon=True)
        ws_started = None
        while time.monotonic() - a0 < args.seconds:
            rss.append(rss_mb(server.pid))
            if ws_started is None and time.monotonic() - a0 >= args.seconds - measure - 1:
                ws_started = time.monotonic()
                ws_thread.start()
            time.sleep(1)
        ws_thread.join(measure + 60)
        a1 = time.monotonic()
        grpc_during = honest.fps(a0 + 1, a1)
        ws_during = ws_result.get("r", (0.0, ["no result"]))[0]
        # SIGTERM with the attack still running.
        term = time.monotonic()
        server.send_signal(signal.SIGTERM)
        try:
            rc = server.wait(10)
        except subprocess.TimeoutExpired:
            rc = None
        exit_s = time.monotonic() - term
        halt.set()
        honest.stop.set()
        print(f"rapid reset {args.seconds:.0f} s from 127.0.0.9: {counts['streams']} streams sent on "
              f"{counts['connections']} connections ({counts['refused']} refused); server RSS max {max(rss):.0f} MB "
              f"(first {rss[0]:.0f}, last {rss[-1]:.0f}); gRPC client {grpc_before:.1f} -> {grpc_during:.1f} fps, "
              f"WebSocket client {ws_before:.1f} -> {ws_during:.1f} fps; SIGTERM exit {exit_s:.2f} s, status {rc}",
              flush=True)
        if max(rss) >= 300:
            fail(f"RSS reached {max(rss):.0f} MB (target: under 300)")
        if grpc_during < 0.5 * grpc_before or ws_during < 0.5 * ws_before:
            fail("an honest client kept under half its frame rate")
        if rc != 0 or exit_s > 2:
            fail(f"SIGTERM: status {rc} after {exit_s:.2f} s (target: 0 within 2 s)")
        log.seek(0)
        text = log.read().decode(errors="replace")
        lines = len(text.splitlines())
        print(f"  the server's log: {lines} lines, {len(text)} bytes", flush=True)
    finally:
        if server.poll() is None:
            server.kill()
            server.wait()

    # ---- silent streams and the token spray, on a fresh server
    server, port, grpc_port, _ = start(args.haarcast, ["--max-pending", str(args.max_pending)])
    held = []
    try:
        # A known client shows the right token once.
        known = Honest(grpc_port)
        known.start()
        known.wait_frames(1, 120)
        known.stop.set()
        if not known.frames:
            fail(f"the known client got no frame before the spray ({known.error})")
        worst = 0
        for a in range(100):
            source = f"127.0.1.{a + 1}"
            try:
                s = raw_connect(grpc_port, source)
            except OSError:
                continue
            s.sendall(b"".join(session_headers(1 + 2 * i, f"Bearer {TOKEN}") for i in range(8)))
            held.append(s)
            if a % 10 == 9:
                time.sleep(0.2)
                worst = max(worst, metric(port, "haarcast_pending_connections"))
        time.sleep(1)
        worst = max(worst, metric(port, "haarcast_pending_connections"))
        evicted = metric(port, 'haarcast_session_cuts_total{reason="pending_evicted"}')
        print(f"silent: 100 addresses x 8 gRPC streams: live pending at most {worst:.0f} (--max-pending "
              f"{args.max_pending}), {evicted:.0f} evicted", flush=True)
        if worst > args.max_pending:
            fail(f"{worst:.0f} live pending streams against --max-pending {args.max_pending}")
        for s in held:
            s.close()
        held.clear()

        # 1,000 wrong tokens from 200 addresses, 5 streams each.
        answered = 0
        for a in range(200):
            try:
                s = raw_connect(grpc_port, f"127.0.2.{a + 1}")
                s.sendall(b"".join(session_headers(1 + 2 * i, "Bearer wrong") for i in range(5)))
                s.settimeout(1)
                try:
                    answered += len(s.recv(65536)) > 0
                except OSError:
                    pass
                s.close()
            except OSError:
                pass
        known = Honest(grpc_port)
        known.start()
        known.wait_frames(10, 60)
        known.stop.set()
        newcomer_refused = metric(port, 'haarcast_refusals_total{reason="token_rate_server"}')
        print(f"spray: 1,000 wrong gRPC tokens from 200 addresses ({answered} answered); refusals token_rate_server "
              f"{newcomer_refused:.0f}; the known client then got {len(known.frames)} frames"
              f"{' (' + known.error + ')' if known.error else ''}", flush=True)
        if not known.frames:
            fail("the known client was not served after the spray")
    finally:
        for s in held:
            s.close()
        stop(server)

    # ---- a frame that never returns
    env = dict(os.environ, HAARCAST_TEST_STALL_STAGE="gbuffer")
    server, port, grpc_port, log = start(args.haarcast, ["--level", "4", "--frame-deadline", "1"], env)
    try:
        stuck = Honest(grpc_port)
        stuck.start()
        waited = time.monotonic()
        while stuck.error is None and time.monotonic() - waited < 60:
            time.sleep(0.1)
        time.sleep(0.5)  # the health status follows within its 200 ms poll
        serving = health(grpc_port)
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/readyz", timeout=5) as r:
                readyz = r.status
        except urllib.error.HTTPError as e:
            readyz = e.code
        rc, exit_s = stop(server)
        print(f"stuck frame over gRPC: the client got {stuck.error or 'nothing'}; gRPC health {serving} (2: NOT_SERVING), "
              f"/readyz {readyz}; SIGTERM exit {exit_s:.2f} s, status {rc}", flush=True)
        if not stuck.error or "gbuffer" not in stuck.error:
            fail("the stuck frame's client was not told the stage")
        if serving != 2 or readyz != 503:
            fail("gRPC health and /readyz do not report the stuck device")
        if rc != 0 or exit_s > 2:
            fail(f"SIGTERM with a stuck frame: status {rc} after {exit_s:.2f} s (target: 0 within 2 s)")
    finally:
        if server.poll() is None:
            server.kill()
    print("PASS")


if __name__ == "__main__":
    main()
