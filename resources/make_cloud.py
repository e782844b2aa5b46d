#!/usr/bin/env python3
"""Writes resources/cloud/cloud.npy (+ its sidecar): the small cumulus of resources/cloud.sylva.json.

Generator-free stand-in (no `sylva volume cloud` yet): a union of soft spheres, its surface displaced by
a deterministic value noise; density in [0, 1], float32, shape (X, Y, Z), z fastest. Standard library only.
"""
import json
import math
import os
import struct

NX, NY, NZ = 40, 24, 40
SPACING = 0.4                        # metres: 16 x 9.6 x 16 m
ORIGIN = (-(NX - 1) * SPACING / 2, -(NY - 1) * SPACING / 2, -(NZ - 1) * SPACING / 2)
BLOBS = [  # centre (metres, grid frame centred), radius
    ((0.0, -0.8, 0.0), 4.6), ((3.4, -1.4, 1.0), 3.4), ((-3.6, -1.2, -0.6), 3.6),
    ((0.8, 1.6, 0.4), 3.4), ((-1.2, 0.6, 3.0), 3.0), ((1.0, -0.6, -3.4), 3.2),
]


def hash01(i, j, k):
    h = (i * 73856093) ^ (j * 19349663) ^ (k * 83492791)
    h &= 0xFFFFFFFF
    h ^= h >> 13
    h = (h * 0x5BD1E995) & 0xFFFFFFFF
    h ^= h >> 15
    return h / 4294967295.0


def value_noise(x, y, z):
    i, j, k = math.floor(x), math.floor(y), math.floor(z)
    fx, fy, fz = x - i, y - j, z - k
    sx, sy, sz = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy), fz * fz * (3 - 2 * fz)
    out = 0.0
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                w = (sx if dx else 1 - sx) * (sy if dy else 1 - sy) * (sz if dz else 1 - sz)
                out += w * hash01(i + dx, j + dy, k + dz)
    return out


def density(p):
    f = -1e9
    for c, r in BLOBS:
        d = math.dist(p, c)
        f = max(f, 1.0 - d / r)      # > 0 inside a blob
    n = 0.0
    amp, freq = 0.5, 0.45
    for _ in range(3):
        n += amp * (value_noise(p[0] * freq, p[1] * freq, p[2] * freq) - 0.5)
        amp *= 0.5
        freq *= 2.0
    f += 0.35 * n
    if f <= 0.0:
        return 0.0
    return min(1.0, f / 0.25) * 0.9


def main():
    here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "cloud")
    os.makedirs(here, exist_ok=True)
    values = []
    for i in range(NX):
        for j in range(NY):
            for k in range(NZ):
                p = (ORIGIN[0] + i * SPACING, ORIGIN[1] + j * SPACING, ORIGIN[2] + k * SPACING)
                values.append(density(p))
    header = "{'descr': '<f4', 'fortran_order': False, 'shape': (%d, %d, %d), }" % (NX, NY, NZ)
    pad = 64 - (10 + len(header) + 1) % 64
    header = header + " " * pad + "\n"
    path = os.path.join(here, "cloud.npy")
    with open(path, "wb") as f:
        f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode("latin1"))
        f.write(struct.pack("<%df" % len(values), *values))
    with open(path + ".json", "w") as f:
        json.dump({"version": 1, "kind": "density", "dims": [NX, NY, NZ], "origin": list(ORIGIN), "spacing": SPACING}, f)
        f.write("\n")
    print(path, "%d nodes, %d with medium" % (len(values), sum(1 for v in values if v > 0)))


if __name__ == "__main__":
    main()
