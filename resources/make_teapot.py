#!/usr/bin/env python3
"""Writes resources/teapot/teapot.obj (+ teapot.mtl): the PMMA teapot of resources/teapot.sylva.json.

A coarser copy of tests/data/models/teapot.obj (the Newell teapot as three.js r187 TeapotGeometry
tessellates it: 32 Bezier patches of 17 x 17 vertices, 16 segments). Every second row and column of
each patch's vertex grid is kept (8 segments: the kept vertices lie on the same patches), vertices
closer than 1e-5 welded, degenerate triangles dropped. The open edges stay open (the spout's tip,
the ends of handle and spout inside the body, the rim under the lid): the solid voxelizer's winding
numbers must fill it anyway. Standard library only:

    python3 resources/make_teapot.py [tests/data/models/teapot.obj]
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "..", "tests", "data", "models", "teapot.obj")
SIDE = 17            # vertices per patch side in the source (16 segments)
KEEP = 2             # every second row and column: 8 segments


def main():
    verts = []
    for line in open(SRC):
        if line.startswith("v "):
            verts.append(tuple(float(c) for c in line.split()[1:4]))
    per = SIDE * SIDE
    if len(verts) % per:
        sys.exit("%s: %d vertices, not a whole number of %d x %d patches" % (SRC, len(verts), SIDE, SIDE))
    index, out_verts, tris = {}, [], []

    def weld(p):
        key = tuple(round(c * 1e5) for c in p)
        if key not in index:
            index[key] = len(out_verts)
            out_verts.append(p)
        return index[key]

    side = (SIDE - 1) // KEEP + 1
    for patch in range(len(verts) // per):
        grid = [[weld(verts[patch * per + (r * KEEP) * SIDE + c * KEEP]) for c in range(side)] for r in range(side)]
        for r in range(side - 1):
            for c in range(side - 1):
                a, b, d, e = grid[r][c], grid[r][c + 1], grid[r + 1][c], grid[r + 1][c + 1]
                # the source's winding: (r, c), (r, c + 1), (r + 1, c + 1) and (r, c), (r + 1, c + 1), (r + 1, c)
                for t in ((a, b, e), (a, e, d)):
                    if len(set(t)) == 3:
                        tris.append(t)
    folder = os.path.join(HERE, "teapot")
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "teapot.mtl"), "w") as f:
        f.write("# PMMA (acrylic) as a taillight: red diffuse, a plastic's white highlight\n")
        f.write("newmtl pmma\nKd 0.72 0.10 0.08\nKs 0.35 0.35 0.35\nNs 48\n")
    with open(os.path.join(folder, "teapot.obj"), "w") as f:
        f.write("# Newell teapot (public-domain patch data) as three.js r187 TeapotGeometry tessellates it (MIT, "
                "LICENSE.three.MIT.txt),\n# every second vertex row and column kept by resources/make_teapot.py: "
                "%d vertices, %d triangles, open edges kept\n" % (len(out_verts), len(tris)))
        f.write("mtllib teapot.mtl\no teapot\nusemtl pmma\n")
        for p in out_verts:
            f.write("v %s\n" % " ".join(("%.5f" % c).rstrip("0").rstrip(".") if c else "0" for c in p))
        for t in tris:
            f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))
    print("wrote %s: %d vertices, %d triangles" % (os.path.join(folder, "teapot.obj"), len(out_verts), len(tris)))


if __name__ == "__main__":
    main()
