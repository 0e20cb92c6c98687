#!/usr/bin/env python3
"""Writes the fuzz targets' seed corpora into corpus/<target>/ (committed).

Small valid files of every shape each loader reads, built byte by byte from
the formats' own descriptions (the same ones the loaders cite), so the fuzzer
starts from inputs that reach deep into each parser. Run it again after a
format change: python3 tests/fuzz/make_corpus.py
"""
import json
import pathlib
import struct

OUT = pathlib.Path(__file__).resolve().parent / "corpus"


def put(target, name, data):
    d = OUT / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data if isinstance(data, bytes) else data.encode())


# Radiance RGBE: flat, old-style runs, new-style runs, flipped axes.
def hdr(res, body, extra=""):
    return f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n{extra}\n{res}\n".encode() + body


put("fuzz_hdr", "flat", hdr("-Y 2 +X 2", bytes([128, 64, 32, 129] * 4)))
put("fuzz_hdr", "old_runs", hdr("+Y 2 -X 4", bytes([128, 64, 32, 129, 1, 1, 1, 3] * 2), "EXPOSURE=2.0\n"))
row = bytes([2, 2, 0, 8]) + b"".join(bytes([128 + 8, v]) for v in (100, 50, 25, 130))
put("fuzz_hdr", "new_runs", hdr("-Y 2 +X 8", row * 2))
# PFM: colour little-endian, grey big-endian.
put("fuzz_pfm", "colour", b"PF\n2 2\n-1.0\n" + struct.pack("<12f", *[0.5 * k for k in range(12)]))
put("fuzz_pfm", "grey_be", b"Pf\n3 1\n1.0\n" + struct.pack(">3f", 1.0, 2.0, 3.0))


# OpenEXR, uncompressed scanlines ("File Layout"): magic, version 2, the
# required attributes, an offset table, one chunk per line.
def attr(name, kind, value):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def exr(width, height, channels, pixel_type=2):  # 2 = FLOAT, 1 = HALF
    size = 4 if pixel_type == 2 else 2
    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", pixel_type, 0, 1, 1) for c in channels) + b"\0"
    box = struct.pack("<4i", 0, 0, width - 1, height - 1)
    header = (attr("channels", "chlist", chlist) + attr("compression", "compression", b"\0") +
              attr("dataWindow", "box2i", box) + attr("displayWindow", "box2i", box) +
              attr("lineOrder", "lineOrder", b"\0") + attr("pixelAspectRatio", "float", struct.pack("<f", 1)) +
              attr("screenWindowCenter", "v2f", struct.pack("<2f", 0, 0)) +
              attr("screenWindowWidth", "float", struct.pack("<f", 1)) + b"\0")
    start = 8 + len(header) + 8 * height
    line = width * size * len(channels)
    offsets = b"".join(struct.pack("<Q", start + y * (8 + line)) for y in range(height))
    chunks = b""
    for y in range(height):
        pixels = b"".join((struct.pack("<f", 0.25 * (x + y)) if size == 4 else struct.pack("<e", 0.25 * (x + y)))
                          for _ in channels for x in range(width))
        chunks += struct.pack("<ii", y, line) + pixels
    return bytes([0x76, 0x2F, 0x31, 0x01]) + struct.pack("<i", 2) + header + offsets + chunks


put("fuzz_exr", "rgb_float", exr(3, 2, ["B", "G", "R"]))
put("fuzz_exr", "y_half", exr(2, 2, ["Y"], pixel_type=1))

# PLY: ASCII with normals and an extra property, binary both ways.
PLY_ASCII = ("ply\nformat ascii 1.0\ncomment seed\nelement vertex 4\nproperty float x\nproperty float y\n"
             "property float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty uchar red\n"
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
             "0 0 0 0 0 1 9\n1 0 0 0 0 1 9\n1 1 0 0 0 1 9\n0 1 0 0 0 1 9\n4 0 1 2 3\n")
put("fuzz_ply", "ascii", PLY_ASCII)
for name, fmt, end in (("binary_le", "binary_little_endian", "<"), ("binary_be", "binary_big_endian", ">")):
    head = (f"ply\nformat {fmt} 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n").encode()
    body = struct.pack(end + "9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack(end + "B3i", 3, 0, 1, 2)
    put("fuzz_ply", name, head + body)

# OBJ: positions only, with normals and texture coordinates, a quad, negative indices.
put("fuzz_obj", "plain", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
put("fuzz_obj", "normals_quad", "o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\n"
                                "f 1/1/1 2/1/1 3/1/1 4/1/1\n")
put("fuzz_obj", "relative", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\ng rest\ns 1\n")

# MERL: the target spreads its input over a whole file (header, then doubles).
put("fuzz_merl", "constant", struct.pack("<3i", 90, 90, 180) + struct.pack("<2d", 1.0, 0.5))
put("fuzz_merl", "below_horizon", struct.pack("<3i", 90, 90, 180) + struct.pack("<3d", -1.0, 2.0, float("nan")))

# Scenes: built-in meshes and analytic materials (files resolve to nothing).
put("fuzz_scene", "builtin", json.dumps({
    "environment": {"builtin": "sky"},
    "camera": {"eye": [0, 0.5, 4], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 40},
    "objects": [{"name": "ball", "mesh": {"builtin": "sphere"}, "material": "phong:64", "translate": [0.7, 0, 0],
                 "scale": 0.5},
                {"mesh": {"builtin": "box"}, "material": "ggx:0.3", "rotate": [0, 30, 0], "fit": False}]}))
put("fuzz_scene", "files", json.dumps({"environment": {"file": "probe.hdr", "layout": "latlong"},
                                       "objects": [{"mesh": "bunny.ply", "material": "steel.binary"}]}))


# Protocol: protobuf wire format by hand (varint keys, length-delimited
# submessages), each message after its 2-byte little-endian length.
def varint(v):
    out = b""
    while True:
        b, v = v & 0x7F, v >> 7
        out += bytes([b | (0x80 if v else 0)])
        if not v:
            return out


def field(number, value):
    if isinstance(value, bytes):
        return varint(number << 3 | 2) + varint(len(value)) + value
    if isinstance(value, float):
        return varint(number << 3 | 1) + struct.pack("<d", value)
    return varint(number << 3 | 0) + varint(value)


def vec3(x, y, z):
    return field(1, float(x)) + field(2, float(y)) + field(3, float(z))


def frames(*messages):
    return b"".join(struct.pack("<H", len(m)) + m for m in messages)


settings = field(1, 5) + field(2, 4) + field(3, 64) + field(4, 1) + field(5, 1.5) + field(6, 2)
hello = (field(1, 1) + field(3, 64) + field(4, 32) + field(5, 2) + field(6, 10.0) + field(7, 80) +
         field(8, b"seed") + field(9, field(1, b"default") + field(2, field(1, 1) + field(2, b"lambert"))) +
         field(10, settings))
pose = field(1, 2) + field(2, field(1, vec3(0, 0, 4)) + field(4, 45.0)) + \
    field(3, field(1, 1) + field(2, vec3(10, 20, 30)) + field(3, vec3(0.1, 0, 0))) + \
    field(4, vec3(0, 90, 0)) + field(5, 12.5)
put("fuzz_protocol", "hello_pose", frames(field(1, hello), field(2, pose), field(5, field(1, 7))))
put("fuzz_protocol", "settings_scene", frames(field(1, field(1, 1)), field(3, settings),
                                              field(4, field(1, b"other")), field(2, field(1, 3))))
put("fuzz_protocol", "text_and_bad", struct.pack("<H", 0x8000 | 5) + b"hello" + frames(field(1, hello), b"\xff\xff",
                                                                                      field(2, pose)))


# WebSocket: byte 0 is the read size - 1; then an HTTP upgrade and masked
# client frames (RFC 6455 §5.2, §5.3).
def upgrade(target="/ws?token=t", extra=""):
    return (f"GET {target} HTTP/1.1\r\nHost: localhost:8080\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
            f"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n{extra}\r\n").encode()


def ws_frame(opcode, payload, fin=True, mask=b"\x11\x22\x33\x44"):
    head = bytes([(0x80 if fin else 0) | opcode])
    n = len(payload)
    if n < 126:
        head += bytes([0x80 | n])
    elif n < 65536:
        head += bytes([0x80 | 126]) + struct.pack(">H", n)
    else:
        head += bytes([0x80 | 127]) + struct.pack(">Q", n)
    return head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload))


BINARY, TEXT, CONTINUATION, CLOSE, PING = 2, 1, 0, 8, 9
session = [ws_frame(BINARY, field(1, hello)), ws_frame(BINARY, field(2, pose)),
           ws_frame(PING, b"p"), ws_frame(BINARY, field(5, field(1, 7)))]
put("fuzz_websocket", "session", bytes([255]) + upgrade("/ws?token=t", "Origin: http://localhost:8080\r\n") +
    b"".join(session) + ws_frame(CLOSE, struct.pack(">H", 1000) + b"bye"))
message = field(1, hello)
put("fuzz_websocket", "fragmented_bearer", bytes([6]) + upgrade("/ws", "Authorization: bearer t\r\n") +
    ws_frame(BINARY, message[:5], fin=False) + ws_frame(PING, b"") + ws_frame(CONTINUATION, message[5:]) +
    ws_frame(TEXT, "settings ☃".encode()) + ws_frame(BINARY, field(3, settings)))
put("fuzz_websocket", "foreign_origin", bytes([255]) + upgrade("/ws?token=t", "Origin: https://evil.example\r\n"))
put("fuzz_websocket", "wrong_token", bytes([255]) + upgrade("/ws?token=x"))
put("fuzz_websocket", "too_large", bytes([255]) + upgrade() + ws_frame(BINARY, bytes(20000)))
