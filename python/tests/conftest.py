"""Shared helpers of the rrt package's tests: the `rrt` command line to
compare with, a PNG decoder, the test scenes and a synthetic volume."""

import os
import pathlib
import struct
import subprocess
import zlib

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
DATA = pathlib.Path(__file__).resolve().parent / "data"
BALL = DATA / "ball.nff"


def cli_path():
    """The `rrt` binary: $RRT_CLI, else the workspace's debug or release
    build (`cargo test --workspace` builds target/debug/rrt)."""
    given = os.environ.get("RRT_CLI")
    if given:
        return pathlib.Path(given)
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    for profile in ("debug", "release"):
        p = target / profile / "rrt"
        if p.exists():
            return p
    pytest.fail("no rrt binary to compare with: run `cargo build -p rrt-host` or set RRT_CLI")


def run_cli(*args):
    """Runs the `rrt` command line; returns (exit status, stderr)."""
    r = subprocess.run([str(cli_path()), *map(str, args)], capture_output=True, text=True)
    return r.returncode, r.stderr


def read_png(path):
    """The pixels of an 8-bit RGB PNG as an (H, W, 3) uint8 array."""
    data = pathlib.Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    assert (depth, colour, interlace) == (8, 2, 0), "8-bit RGB, not interlaced"
    raw = zlib.decompress(idat)
    stride = 3 * width
    out = np.zeros((height, stride), dtype=np.int32)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int32)
        prev = out[y - 1] if y else np.zeros(stride, np.int32)
        if f == 0:
            cur = line
        elif f == 2:
            cur = (line + prev) & 255
        else:
            # Sub, Average and Paeth depend on the pixel to the left.
            cur = np.zeros(stride, np.int32)
            for x in range(stride):
                a = cur[x - 3] if x >= 3 else 0
                b = prev[x]
                c = prev[x - 3] if x >= 3 else 0
                if f == 1:
                    p = a
                elif f == 3:
                    p = (a + b) // 2
                else:
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[x] = (line[x] + p) & 255
        out[y] = cur
    return out.astype(np.uint8).reshape(height, width, 3)


def sphere_density(n=40, dtype=np.float32):
    """An n³ density, [z, y, x]: two balls (radius 0.3 and 0.15 of the
    box, the smaller one above and to the side), each 1 inside and 0
    outside with a linear edge whose middle value 0.5 is at its radius."""
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float64) / (n - 1)
    big = 0.5 + (0.3 - np.sqrt((x - 0.42) ** 2 + (y - 0.5) ** 2 + (z - 0.38) ** 2)) / 0.1
    small = 0.5 + (0.15 - np.sqrt((x - 0.72) ** 2 + (y - 0.5) ** 2 + (z - 0.78) ** 2)) / 0.1
    d = np.clip(np.maximum(big, small), 0.0, 1.0)
    if np.issubdtype(dtype, np.integer):
        d = d * np.iinfo(dtype).max
    return np.ascontiguousarray(d.astype(dtype))
