#!/usr/bin/env python3
"""The Python gRPC client of docs/service.md, run as written: its two code
blocks are cut out of the page, the client saved as orbit.py in an empty
folder and the shell block run there by bash, as a reader would, with
HAARCAST, SERVER and TOKEN set and a PATH whose first python3 has no grpc
module (the shell block must not depend on it), against `haarcast serve
--grpc-port` on loopback. Then every saved frame must be a 256×256 RGBA PNG
that decodes, the orbit must show different views, and nothing may have been
written into the repository. Before that, with raw calls (no stubs), the
health service must answer SERVING, and reflection v1 and v1alpha must both
list the services; v1 must describe haarcast.v1.Render (its file,
haarcast.proto) and answer NOT_FOUND for a symbol that does not exist.

usage: grpc_docs_client.py --haarcast BIN --docs docs/service.md --proto proto/haarcast.proto
Exit 77 (skip) when grpc or protobuf is missing from Debian's /usr/bin/python3.
"""
import argparse
import os
import re
import shutil
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


DEBIAN_PYTHON = "/usr/bin/python3"


def block_from(docs, language, first_line):
    """The ```language block that starts with first_line."""
    blocks = re.findall(rf"```{language}\n(.*?)```", open(docs, encoding="utf-8").read(), re.S)
    found = [b for b in blocks if b.startswith(first_line)]
    if len(found) != 1:
        fail(f"{docs}: {len(found)} {language} blocks start with {first_line!r}, expected 1")
    return found[0]


def varint(n):
    out = b""
    while True:
        byte, n = n & 0x7F, n >> 7
        out += bytes([byte | (0x80 if n else 0)])
        if not n:
            return out


def field(number, payload):
    """A length-delimited protobuf field."""
    return varint(number << 3 | 2) + varint(len(payload)) + payload


def reflection(channel, version, request):
    """One ServerReflectionRequest, raw, on a stream of its own: the answer's bytes."""
    call = channel.stream_stream(f"/grpc.reflection.{version}.ServerReflection/ServerReflectionInfo")
    return b"".join(call(iter([request]), timeout=10))


def repo_files(repo):
    """The repository's files outside build folders and .git (what a run must not add to)."""
    out = set()
    for root, dirs, files in os.walk(repo):
        dirs[:] = [d for d in dirs if d != ".git" and not d.startswith("build") and d != "node_modules"]
        out.update(os.path.relpath(os.path.join(root, f), repo) for f in files)
    return out


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
    if subprocess.run([DEBIAN_PYTHON, "-c", "import grpc, google.protobuf"], capture_output=True).returncode != 0:
        print(f"SKIP: {DEBIAN_PYTHON} has no grpc module (apt-get install python3-grpcio python3-protobuf)")
        return SKIP

    # The reader's folder: orbit.py as the page has it, nothing else.
    work = tempfile.mkdtemp(prefix="haarcast-grpc-docs-")
    script = os.path.join(work, "orbit.py")
    with open(script, "w", encoding="utf-8") as f:
        f.write(block_from(opts.docs, "python", "# orbit.py"))
    shell = block_from(opts.docs, "sh", "# run-orbit.sh")
    repo = os.path.dirname(os.path.dirname(os.path.abspath(opts.proto)))
    # A python3 first on the PATH without grpc (a virtual environment's, say),
    # and grpc_python_plugin where the build found it.
    fake_bin = os.path.join(work, "fake-bin")
    os.mkdir(fake_bin)
    with open(os.path.join(fake_bin, "python3"), "w", encoding="utf-8") as f:
        f.write("#!/bin/sh\necho \"ModuleNotFoundError: No module named 'grpc' (a python3 that is not Debian's)\" >&2\nexit 1\n")
    os.chmod(os.path.join(fake_bin, "python3"), 0o755)
    plugin = shutil.which(opts.grpc_python_plugin) or opts.grpc_python_plugin
    path = os.pathsep.join([fake_bin, os.path.dirname(os.path.abspath(plugin)), os.environ.get("PATH", "")])
    frames = os.path.join(work, "frames")
    before = repo_files(repo)

    def run_block(token, timeout):
        env = dict(os.environ, PATH=path, HAARCAST=repo, SERVER=f"127.0.0.1:{port}", TOKEN=token)
        env.pop("PYTHONPATH", None)
        return subprocess.run(["bash", "-euo", "pipefail", "-c", shell], cwd=work, env=env,
                              capture_output=True, text=True, timeout=timeout)

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
        # Reflection, both versions: ServerReflectionRequest{list_services: ""} (field 7).
        for version in ("v1", "v1alpha"):
            listing = reflection(channel, version, field(7, b""))
            for name in (b"haarcast.v1.Render", b"grpc.health.v1.Health", b"grpc.reflection.v1.ServerReflection"):
                if name not in listing:
                    fail(f"reflection {version} does not list {name.decode()}: {listing!r}")
        # v1 describes the service: file_containing_symbol (field 4) → the
        # FileDescriptorResponse (field 4) of haarcast.proto, which declares it.
        described = reflection(channel, "v1", field(4, b"haarcast.v1.Render"))
        if b"haarcast.proto" not in described or b"Session" not in described:
            fail(f"reflection v1 does not describe haarcast.v1.Render: {described[:200]!r}")
        # An unknown symbol: ErrorResponse (field 7) with NOT_FOUND (5).
        missing = reflection(channel, "v1", field(4, b"haarcast.v1.NoSuchThing"))
        if b"\x08\x05" not in missing or b"no symbol named haarcast.v1.NoSuchThing" not in missing:
            fail(f"reflection v1 answers an unknown symbol with {missing!r}, expected NOT_FOUND")

        run = run_block(TOKEN, 120)
        if run.returncode != 0:
            fail(f"the docs' shell block exited {run.returncode}: {run.stderr[-2000:]}")
        if repo_files(repo) != before:
            fail(f"running the docs' blocks wrote into {repo}: {sorted(repo_files(repo) - before)}")
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
        wrong = run_block("wrong", 60)
        if wrong.returncode == 0 or "UNAUTHENTICATED" not in wrong.stderr:
            fail(f"a wrong token: exit {wrong.returncode}, stderr {wrong.stderr[-500:]!r}")
    finally:
        server.send_signal(signal.SIGTERM)
        try:
            code = server.wait(timeout=10)
        except subprocess.TimeoutExpired:
            server.kill()
            fail("the server did not exit within 10 s of SIGTERM")
        finally:
            shutil.rmtree(work, ignore_errors=True)  # the reader's folder, stubs and frames
    if code != 0:
        fail(f"the server exited {code} after SIGTERM")
    print(f"PASS: the docs' blocks run as written; {STEPS} frames of the orbit decode ({len(pictures)} different), "
          "health SERVING, reflection v1 and v1alpha list the services and v1 describes them, a wrong token is "
          "UNAUTHENTICATED, SIGTERM exits 0")
    return 0


if __name__ == "__main__":
    sys.exit(main())
