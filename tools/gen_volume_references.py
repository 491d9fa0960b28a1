#!/usr/bin/env python3
"""Writes the grids of the volume references in tests/references/ (Mitsuba .vol files, version 3,
32-bit floats, on the unit cube). Run from the repository's root.

* rgb_albedo.vol: 6 x 5 x 4 voxels of three channels, an albedo that changes colour across the
  grid, (0.15 + 0.8 x, 0.2 + 0.7 y (1 - x), 0.9 - 0.75 z) at the voxel centres.
* rgb_sigma_t.vol: 4 x 4 x 4 voxels of three channels, a chromatic extinction,
  (0.5 + 2 x, 1.5 - y, 0.3 + 1.2 z x).
* density.vol: 8 x 8 x 8 voxels of one channel, a smooth blob, 0.2 + 1.8 exp(-6 |p - c|^2).
* roughness.vol: 5 x 5 x 5 voxels of one channel, a roughness, 0.1 + 0.6 y (1 - 0.5 z) + 0.2 x.
"""
import math
import struct


def write(path, res, channels, value):
    nx, ny, nz = res
    data = []
    for z in range(nz):
        for y in range(ny):
            for x in range(nx):
                p = ((x + 0.5) / nx, (y + 0.5) / ny, (z + 0.5) / nz)
                v = value(*p)
                data.extend(v if channels > 1 else [v])
    header = b"VOL\x03" + struct.pack("<i", 1) + struct.pack("<4i", nx, ny, nz, channels)
    header += struct.pack("<6f", 0, 0, 0, 1, 1, 1)
    with open(path, "wb") as f:
        f.write(header + struct.pack(f"<{len(data)}f", *data))


write("tests/references/rgb_albedo.vol", (6, 5, 4), 3,
      lambda x, y, z: [0.15 + 0.8 * x, 0.2 + 0.7 * y * (1 - x), 0.9 - 0.75 * z])
write("tests/references/rgb_sigma_t.vol", (4, 4, 4), 3,
      lambda x, y, z: [0.5 + 2 * x, 1.5 - y, 0.3 + 1.2 * z * x])
write("tests/references/density.vol", (8, 8, 8), 1,
      lambda x, y, z: 0.2 + 1.8 * math.exp(-6 * ((x - 0.5) ** 2 + (y - 0.5) ** 2 + (z - 0.5) ** 2)))
write("tests/references/roughness.vol", (5, 5, 5), 1,
      lambda x, y, z: 0.1 + 0.6 * y * (1 - 0.5 * z) + 0.2 * x)
