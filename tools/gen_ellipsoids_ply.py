#!/usr/bin/env python3
"""Writes tests/references/ellipsoids.ply: seven ellipsoids in 3D Gaussian splatting's PLY layout
(`x y z nx ny nz f_dc_0 f_dc_1 f_dc_2 opacity scale_0 scale_1 scale_2 rot_0 rot_1 rot_2 rot_3`,
binary little-endian floats), as Mitsuba 3's `ellipsoids` shape reads it: scales stored as
logarithms of the standard deviations (the radii are three times them at the default extent),
opacities as logits, rotations as quaternions (w, x, y, z), some of them not of unit length.
No opacity is at most 0.01: Mitsuba 3.9.1 gives such an ellipsoid NaN radii under adaptive
clamping, which makes its image brighter (docs/mitsuba-compatibility.md).

    python3 tools/gen_ellipsoids_ply.py [OUT]
"""
import math
import struct
import sys

# centre, radii at extent 3 (before clamping), rotation axis and angle in degrees, opacity
ELLIPSOIDS = [
    ((-0.55, 0.0, 0.35), (0.35, 0.15, 0.22), (0, 0, 1), 30, 0.95),
    ((0.45, 0.25, 0.45), (0.22, 0.32, 0.12), (1, 1, 0), 60, 0.6),
    ((0.1, -0.45, 0.3), (0.28, 0.28, 0.28), (0, 1, 0), 0, 0.8),
    ((0.0, 0.3, 0.9), (0.5, 0.08, 0.08), (0.3, -0.2, 1), 110, 0.99),
    ((-0.3, -0.2, 0.9), (0.12, 0.12, 0.3), (1, 0, 0), 45, 0.4),
    ((0.6, -0.3, 0.15), (0.15, 0.3, 0.15), (0, 0, 1), -20, 0.05),
    ((-0.2, 0.55, 0.2), (0.2, 0.1, 0.2), (1, -1, 1), 75, 0.7),
]
NAMES = ("x y z nx ny nz f_dc_0 f_dc_1 f_dc_2 opacity scale_0 scale_1 scale_2 "
         "rot_0 rot_1 rot_2 rot_3").split()


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "tests/references/ellipsoids.ply"
    header = "ply\nformat binary_little_endian 1.0\nelement vertex %d\n" % len(ELLIPSOIDS)
    header += "".join("property float %s\n" % name for name in NAMES) + "end_header\n"
    with open(out, "wb") as f:
        f.write(header.encode())
        for i, (centre, radii, axis, angle, opacity) in enumerate(ELLIPSOIDS):
            norm = math.sqrt(sum(c * c for c in axis))
            half = math.radians(angle) / 2
            length = 1.0 + 0.5 * (i % 3)  # Mitsuba normalises the quaternions it reads
            quat = [length * math.cos(half)] + [length * c / norm * math.sin(half) for c in axis]
            logs = [math.log(r / 3.0) for r in radii]
            logit = math.log(opacity / (1.0 - opacity))
            row = list(centre) + [0.0, 0.0, 1.0] + [0.5, 0.2, 0.1] + [logit] + logs + quat
            f.write(struct.pack("<%df" % len(row), *row))


if __name__ == "__main__":
    main()
