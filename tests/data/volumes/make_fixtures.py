#!/usr/bin/env python3
"""Writes the small NRRD fixtures of tests/volumes.rs (independently of
rrt's own NRRD writer). Every file holds the same 5x4x3 grid, x fastest,
f(i, j, k) = i + 5 j + 20 k (0..59), stored per type as:
  uint8  f          int16  f - 30          uint16  1000 f
  float  0.25 f - 3
Run from this folder: python3 make_fixtures.py
"""
import gzip
import struct

NX, NY, NZ = 5, 4, 3
F = [i + 5 * j + 20 * k for k in range(NZ) for j in range(NY) for i in range(NX)]


def write(name, header, data):
    with open(name, "wb") as f:
        f.write(header.encode() + data)


u8 = bytes(F)
write("u8_raw.nrrd",
      "NRRD0004\n# uint8, raw, space directions and origin\ntype: uint8\ndimension: 3\n"
      "space: right-anterior-superior\nsizes: 5 4 3\n"
      "space directions: (0.5,0,0) (0,0.5,0) (0,0,1.5)\nkinds: domain domain domain\n"
      "encoding: raw\nspace origin: (1,2,3)\n\n", u8)
write("u8_gzip.nrrd",
      "NRRD0004\ntype: unsigned char\ndimension: 3\nspace dimension: 3\nsizes: 5 4 3\n"
      "space directions: (0.5, 0, 0) (0, 0.5, 0) (0, 0, 1.5)\nencoding: gzip\n"
      "space origin: (1, 2, 3)\n\n", gzip.compress(u8, mtime=0))
write("i16_be.nrrd",
      "NRRD0003\ntype: short\ndimension: 3\nsizes: 5 4 3\nspacings: 1 1 2\nendian: big\n"
      "encoding: raw\n\n", struct.pack(">%dh" % len(F), *[v - 30 for v in F]))
write("u16_gzip.nrrd",
      "NRRD0005\n# key/value pairs and comments are skipped\nsource:=make_fixtures.py\n"
      "type: ushort\ndimension: 3\nsizes: 5 4 3\nendian: little\nencoding: gz\n"
      "content: fixture\n\n",
      gzip.compress(struct.pack("<%dH" % len(F), *[1000 * v for v in F]), mtime=0))
# Detached header: 16 junk bytes skipped, float little-endian.
with open("f32.raw", "wb") as f:
    f.write(b"JUNKJUNKJUNKJUNK" + struct.pack("<%df" % len(F), *[0.25 * v - 3 for v in F]))
with open("f32.nhdr", "w") as f:
    f.write("NRRD0004\ntype: float\ndimension: 3\nsizes: 5 4 3\nspacings: 0.25 0.5 0.75\n"
            "endian: little\nencoding: raw\nbyte skip: 16\ndata file: f32.raw\n")
# ASCII with a line to skip and data at the end of a raw file (byte skip -1).
write("u8_ascii.nrrd",
      "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4 3\nencoding: ascii\nline skip: 1\n\n",
      b"this line is skipped\n" + "\n".join(" ".join(str(v) for v in F[r:r + 5])
                                             for r in range(0, len(F), 5)).encode() + b"\n")
write("u8_tail.nrrd",
      "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 5 4 3\nencoding: raw\nbyte skip: -1\n\n",
      b"padding before the data" + u8)
