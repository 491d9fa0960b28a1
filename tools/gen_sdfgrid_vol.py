#!/usr/bin/env python3
"""Writes tests/references/sdfgrid.vol: the signed distance to a sphere of radius 0.35 about
(0.52, 0.5, 0.45), sampled on 7 x 7 x 7 points spanning the unit cube (point (i, j, k) at
(i, j, k) / 6), as a single-channel Mitsuba `.vol` file (version 3, 32-bit floats, x varying
fastest). So coarse a grid makes the voxels' trilinear patches and the two normal modes of
`sdfgrid` visibly different.

    python3 tools/gen_sdfgrid_vol.py [OUT]
"""
import math
import struct
import sys

N = 7
CENTRE = (0.52, 0.5, 0.45)
RADIUS = 0.35


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "tests/references/sdfgrid.vol"
    values = []
    for z in range(N):
        for y in range(N):
            for x in range(N):
                p = (x / (N - 1), y / (N - 1), z / (N - 1))
                values.append(math.dist(p, CENTRE) - RADIUS)
    with open(out, "wb") as f:
        f.write(b"VOL" + bytes([3]) + struct.pack("<i", 1))
        f.write(struct.pack("<4i", N, N, N, 1) + struct.pack("<6f", 0, 0, 0, 1, 1, 1))
        f.write(struct.pack("<%df" % len(values), *values))


if __name__ == "__main__":
    main()
