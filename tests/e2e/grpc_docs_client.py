#!/usr/bin/env python3
"""The Python gRPC client of docs/service.md, run as written: its code block
is cut out of the page, Python stubs are generated from proto/haarcast.proto
(protoc + grpc_python_plugin) into a temporary folder, and the script runs
against `haarcast serve --grpc-port` on loopback. Then every saved frame must
be a 256×256 RGBA PNG that decodes, and the orbit must show different views.
Before that, with raw calls (no stubs), the health service must answer
SERVING and reflection must list the services.

usage: grpc_docs_client.py --haarcast BIN --docs docs/service.md --proto proto/haarcast.proto
Exit 77 (skip) when grpc or protobuf is missing from this Python.
"""
import argparse
import os
import re
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import zlib

SKIP = 77
TOKEN = "docs-token"
STEPS = 12


def fail(what):
    print(f"FAIL: {what}", file=sys.stderr)
    sys.exit(1)


def script_from(docs):
    """The ```python block that starts with '# orbit.py'."""
    blocks = re.findall(r"```python\n(.*?)```", open(docs, encoding="utf-8").read(), re.S)
    scripts = [b for b in blocks if b.startswith("# orbit.py")]
    if len(scripts) != 1:
        fail(f"{docs}: {len(scripts)} python blocks start with '# orbit.py', expected 1")
    return scripts[0]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def png_pixels(path):
    """(width, height) of an 8-bit RGBA PNG whose image data inflates to the
    size its header promises; fails otherwise."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(f"{path}: not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if zlib.crc32(kind + body) != struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])[0]:
            fail(f"{path}: bad CRC in {kind}")
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    if not header or header[2:4] != (8, 6):
        fail(f"{path}: not 8-bit RGBA ({header})")
    width, height = header[:2]
    raw = zlib.decompress(idat)
    if len(raw) != height * (1 + 4 * width):
        fail(f"{path}: {len(raw)} bytes of image data, expected {height * (1 + 4 * width)}")
    return width, height, raw


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--haarcast", required=True)
    ap.add_argument("--docs", required=True)
    ap.add_argument("--proto", required=True)
    ap.add_argument("--grpc-python-plugin", default="grpc_python_plugin")
    ap.add_argument("--cache-dir", default="none")
    opts = ap.parse_args()
    try:
        import grpc  # noqa: F401
        import google.protobuf  # noqa: F401
    except ImportError as e:
        print(f"SKIP: {e} (apt-get install python3-grpcio python3-protobuf)")
        return SKIP

    work = tempfile.mkdtemp(prefix="haarcast-grpc-docs-")
    script = os.path.join(work, "orbit.py")
    with open(script, "w", encoding="utf-8") as f:
        f.write(script_from(opts.docs))
    proto_dir = os.path.dirname(os.path.abspath(opts.proto))
    subprocess.run(["protoc", f"-I{proto_dir}", f"--python_out={work}", f"--grpc_out={work}",
                    f"--plugin=protoc-gen-grpc={opts.grpc_python_plugin}", os.path.abspath(opts.proto)], check=True)
    frames = os.path.join(work, "frames")
    os.mkdir(frames)

    port = free_port()
    server = subprocess.Popen([opts.haarcast, "serve", "--port", "0", "--grpc-port", str(port), "--token", TOKEN,
                               "--quiet", "--cache-dir", opts.cache_dir],
                              stdout=subprocess.PIPE, text=True)
    try:
        line = server.stdout.readline()
        if not line.startswith("listening on "):
            fail(f"the server did not start: {line!r}")
        import grpc
        channel = grpc.insecure_channel(f"127.0.0.1:{port}")
        # Health: HealthCheckRequest{} → HealthCheckResponse{status: SERVING (1)}.
        health = channel.unary_unary("/grpc.health.v1.Health/Check")(b"", timeout=10)
        if health != b"\x08\x01":
            fail(f"health check answered {health!r}, expected SERVING (b'\\x08\\x01')")
        # Reflection: ServerReflectionRequest{list_services: ""} (field 7).
        reflect = channel.stream_stream("/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo")
        listing = b"".join(reflect(iter([b"\x3a\x00"]), timeout=10))
        for name in (b"haarcast.v1.Render", b"grpc.health.v1.Health"):
            if name not in listing:
                fail(f"reflection does not list {name.decode()}: {listing!r}")

        run = subprocess.run([sys.executable, script, f"127.0.0.1:{port}", TOKEN, frames], cwd=work,
                             capture_output=True, text=True, timeout=120)
        if run.returncode != 0:
            fail(f"the docs' client exited {run.returncode}: {run.stderr[-2000:]}")
        names = sorted(os.listdir(frames))
        expected = [f"frame{n:02d}.png" for n in range(STEPS)]
        if names != expected:
            fail(f"saved {names}, expected {expected}")
        pictures = set()
        for name in names:
            width, height, raw = png_pixels(os.path.join(frames, name))
            if (width, height) != (256, 256):
                fail(f"{name}: {width}x{height}, expected 256x256")
            pictures.add(zlib.crc32(raw))
        if len(pictures) < STEPS // 2:
            fail(f"only {len(pictures)} different pictures in {STEPS} steps of the orbit")
        # A wrong token: UNAUTHENTICATED, and the script says so.
        wrong = subprocess.run([sys.executable, script, f"127.0.0.1:{port}", "wrong", frames], cwd=work,
                               capture_output=True, text=True, timeout=60)
        if wrong.returncode == 0 or "UNAUTHENTICATED" not in wrong.stderr:
            fail(f"a wrong token: exit {wrong.returncode}, stderr {wrong.stderr[-500:]!r}")
    finally:
        server.send_signal(signal.SIGTERM)
        try:
            code = server.wait(timeout=10)
        except subprocess.TimeoutExpired:
            server.kill()
            fail("the server did not exit within 10 s of SIGTERM")
    if code != 0:
        fail(f"the server exited {code} after SIGTERM")
    print(f"PASS: {STEPS} frames of the docs' orbit decode ({len(pictures)} different), health SERVING, "
          "reflection lists the services, a wrong token is UNAUTHENTICATED, SIGTERM exits 0")
    return 0


if __name__ == "__main__":
    sys.exit(main())
