#!/usr/bin/env python3
"""Writes scenes/parity/mesh_attribute/colours.ply: a 5 x 5 grid of vertices over [-1, 1]^2
(z = 0), two triangles per cell, each vertex one of eight float colours in (0, 1), as a binary
PLY (`red green blue` vertex properties); and face_colours.ply beside it: the same triangles,
each one of the colours (`r g b` face properties after the index list; Mitsuba 3 reads only
triangles from a PLY).

    python3 tools/gen_mesh_attribute_parity.py [OUT]
"""
import os
import struct
import sys

COLOURS = [(0.85, 0.12, 0.1), (0.1, 0.75, 0.15), (0.08, 0.15, 0.85), (0.9, 0.8, 0.1),
           (0.95, 0.93, 0.9), (0.05, 0.05, 0.06), (0.5, 0.25, 0.8), (0.05, 0.7, 0.7)]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/parity/mesh_attribute/colours.ply"
    n = 5
    vertices, faces = [], []
    for j in range(n):
        for i in range(n):
            x, y = -1 + 2 * i / (n - 1), -1 + 2 * j / (n - 1)
            vertices.append((x, y, 0.0) + COLOURS[(i * 3 + j * 5) % len(COLOURS)])
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            faces += [(a, a + 1, a + n + 1), (a, a + n + 1, a + n)]
    header = ("ply\nformat binary_little_endian 1.0\n"
              "comment a grid with vertex colours, for comparing mesh_attribute with Mitsuba 3\n"
              f"element vertex {len(vertices)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              "property float red\nproperty float green\nproperty float blue\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    data = header.encode()
    for v in vertices:
        data += struct.pack("<ffffff", *v)
    for f in faces:
        data += struct.pack("<Biii", 3, *f)
    with open(out, "wb") as f:
        f.write(data)

    header = ("ply\nformat binary_little_endian 1.0\n"
              "comment a grid with face colours, for comparing mesh_attribute with Mitsuba 3\n"
              f"element vertex {len(vertices)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\n"
              "property float r\nproperty float g\nproperty float b\nend_header\n")
    data = header.encode()
    for v in vertices:
        data += struct.pack("<fff", *v[:3])
    for k, f in enumerate(faces):
        data += struct.pack("<Biii", 3, *f) + struct.pack("<fff", *COLOURS[(k * 3) % len(COLOURS)])
    with open(os.path.join(os.path.dirname(out), "face_colours.ply"), "wb") as f:
        f.write(data)


if __name__ == "__main__":
    main()
