"""Writes synthetic.pbsdf, a small table in the format of the KAIST pBRDF database that
Mitsuba 3's `measured_polarized` reads: a Mitsuba tensor file with phi_d, theta_d, theta_h
(float32, shape [1, n], radians), wvls (uint16, shape [5], nm: Mitsuba reads five) and M
(float32, shape [phi_d, theta_d, theta_h, 5, 4, 4]). Every matrix is c [[1, a, 0, 0],
[a, 1, 0, 0], [0, 0, b, s], [0, 0, -s, b]] (the form of a Fresnel reflection) with a = 0.5,
b = 0.7, s = 0.2 and c = (0.08 + 0.1 theta_h / (pi/2)) (1 + (lambda - 450) / 1000)
(1 + 0.3 cos phi_d) (1 - 0.2 theta_d), at most 0.28, so that c pi < 1.

    python3 make_synthetic_pbsdf.py   # needs numpy
"""
import struct

import numpy as np

phi_d = np.linspace(-np.pi, np.pi, 5, dtype=np.float32)
theta_d = np.linspace(0, np.pi / 2, 4, dtype=np.float32)
theta_h = np.linspace(0, np.pi / 2, 5, dtype=np.float32)
wvls = np.array([450, 500, 550, 600, 650], dtype=np.uint16)
shape = np.array([[1, 0.5, 0, 0], [0.5, 1, 0, 0], [0, 0, 0.7, 0.2], [0, 0, -0.2, 0.7]])
pd, td, th, wl = np.meshgrid(phi_d, theta_d, theta_h, wvls.astype(np.float64), indexing="ij")
c = (0.08 + 0.1 * th / (np.pi / 2)) * (1 + (wl - 450) / 1000) * (1 + 0.3 * np.cos(pd)) * (1 - 0.2 * td)
M = (c[..., None, None] * shape).astype(np.float32)

fields = [
    ("phi_d", 10, phi_d.reshape(1, -1)),
    ("theta_d", 10, theta_d.reshape(1, -1)),
    ("theta_h", 10, theta_h.reshape(1, -1)),
    ("wvls", 3, wvls),
    ("M", 10, M),
]
header = 12 + 2 + 4 + sum(2 + len(n) + 2 + 1 + 8 + 8 * a.ndim for n, _, a in fields)
out = bytearray(b"tensor_file\0" + struct.pack("<HI", 1, len(fields)))
offset = (header + 7) // 8 * 8
data = bytearray()
for name, dtype, array in fields:
    out += struct.pack("<H", len(name)) + name.encode() + struct.pack("<HBQ", array.ndim, dtype, offset + len(data))
    out += b"".join(struct.pack("<Q", d) for d in array.shape)
    data += array.tobytes()
    data += b"\0" * (-len(data) % 8)
out += b"\0" * (offset - len(out))
open("synthetic.pbsdf", "wb").write(out + data)
