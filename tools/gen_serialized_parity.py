#!/usr/bin/env python3
"""Writes scenes/parity/serialized/meshes.serialized: two shapes of Mitsuba's serialized format
(version 4), a ground quad (shape 0: single precision, positions only, so the reader computes its
normals) and a torus (shape 1: double precision, with vertex normals and texture coordinates).

    python3 tools/gen_serialized_parity.py [OUT]
"""
import math
import struct
import sys
import zlib

HAS_NORMALS, HAS_TEXCOORDS = 0x0001, 0x0002
SINGLE, DOUBLE = 0x1000, 0x2000


def shape(name, positions, triangles, normals=None, uvs=None, double=False):
    """The header and zlib stream of one version-4 shape."""
    flags = DOUBLE if double else SINGLE
    flags |= HAS_NORMALS if normals else 0
    flags |= HAS_TEXCOORDS if uvs else 0
    number = "<d" if double else "<f"
    body = struct.pack("<I", flags) + name.encode() + b"\0"
    body += struct.pack("<QQ", len(positions), len(triangles))
    for array in (positions, normals, uvs):
        for vector in array or []:
            body += b"".join(struct.pack(number, v) for v in vector)
    for triangle in triangles:
        body += struct.pack("<3I", *triangle)
    return struct.pack("<HH", 0x041C, 4) + zlib.compress(body, 9)


def quad():
    positions = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
    return shape("ground", positions, [(0, 1, 2), (2, 3, 0)])


def torus(major=0.45, minor=0.2, rings=24, sides=12):
    """A torus around z; vertex (i, j) at ring angle 2πi/rings and tube angle 2πj/sides."""
    positions, normals, uvs, triangles = [], [], [], []
    for i in range(rings + 1):
        u = 2 * math.pi * i / rings
        for j in range(sides + 1):
            v = 2 * math.pi * j / sides
            n = (math.cos(v) * math.cos(u), math.cos(v) * math.sin(u), math.sin(v))
            c = (major * math.cos(u), major * math.sin(u), 0.0)
            positions.append(tuple(c[k] + minor * n[k] for k in range(3)))
            normals.append(n)
            uvs.append((i / rings, j / sides))
    for i in range(rings):
        for j in range(sides):
            a = i * (sides + 1) + j
            b = a + sides + 1
            triangles += [(a, b, b + 1), (a, b + 1, a + 1)]
    return shape("torus", positions, triangles, normals, uvs, double=True)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/parity/serialized/meshes.serialized"
    shapes = [quad(), torus()]
    data, offsets = b"", []
    for s in shapes:
        offsets.append(len(data))
        data += s
    data += b"".join(struct.pack("<Q", o) for o in offsets) + struct.pack("<I", len(shapes))
    with open(out, "wb") as f:
        f.write(data)


if __name__ == "__main__":
    main()
