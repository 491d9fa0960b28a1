#!/usr/bin/env python3
"""Writes scenes/media/smoke.vol: a 16 x 16 x 16 single-channel Mitsuba .vol grid (version 3,
32-bit floats) of a smooth puff, density(x) = max(0, 1 - |x - c|^2 / 0.2) * (0.6 + 0.4 sin(9 x) sin(7 y)),
on the unit cube. Run from the repository's root."""
import math
import struct

N = 16
values = []
for z in range(N):
    for y in range(N):
        for x in range(N):
            p = [(x + 0.5) / N, (y + 0.5) / N, (z + 0.5) / N]
            r2 = sum((c - 0.5) ** 2 for c in p)
            puff = max(0.0, 1.0 - r2 / 0.2)
            values.append(puff * (0.6 + 0.4 * math.sin(9 * p[0]) * math.sin(7 * p[1])))
header = b"VOL\x03" + struct.pack("<i", 1) + struct.pack("<4i", N, N, N, 1)
header += struct.pack("<6f", 0, 0, 0, 1, 1, 1)
with open("scenes/media/smoke.vol", "wb") as f:
    f.write(header + struct.pack(f"<{len(values)}f", *values))
