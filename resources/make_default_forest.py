#!/usr/bin/env python3
"""Writes default_forest.sylva.json: the composition of Table 2 of Geist & Steele,
"A Lighting Model for Fast Rendering of Forest Ecosystems" (five broadleaf species,
962 instances, ~273 million instanced triangles) scattered on a jittered grid, deterministic.
Run from this folder: python3 make_default_forest.py"""
import json
import random

SPECIES = [
    # name, grower species, seed, triangles, height (m), instances
    ("red maple", "broadleaf", 11, 115529, 15.0, 12),
    ("ohio buckeye", "broadleaf", 12, 168520, 10.0, 285),
    ("paper birch", "birch", 13, 372896, 16.0, 291),
    ("southern catalpa", "broadleaf", 14, 155342, 11.0, 206),
    ("american beech", "broadleaf", 15, 496719, 18.0, 168),
]

rng = random.Random(2008)
names = [s[0] for s in SPECIES for _ in range(s[5])]
rng.shuffle(names)
cols, rows, cell = 32, 31, 7.0        # 992 cells of 7 m; 962 of them get a tree
cells = [(i, j) for j in range(rows) for i in range(cols)]
rng.shuffle(cells)
instances = []
for name, (i, j) in zip(names, sorted(cells[:len(names)], key=lambda c: (c[1], c[0]))):
    x = (i - cols / 2 + rng.uniform(0.15, 0.85)) * cell
    z = (j + rng.uniform(0.15, 0.85)) * cell
    instances.append({"species": name, "position": [round(x, 3), 0.0, round(z, 3)],
                      "rotation": round(rng.uniform(0.0, 360.0), 2), "scale": round(rng.uniform(0.8, 1.2), 3)})

scene = {
    "version": 1,
    "species": [{"name": n, "grow": {"species": g, "seed": s, "triangles": t, "height": h},
                 "lighting": {"preset": "leaf", "grid": 64}} for n, g, s, t, h, _ in SPECIES],
    "instances": instances,
    "ground": {"enabled": True, "height": 0.0, "color": [0.16, 0.13, 0.08]},
    "sun": {"elevation": 45.0, "azimuth": 150.0, "temperature": 6500, "intensity": 1.0},
    "sky": {"color": [0.45, 0.6, 0.85]},
    "camera": {"position": [0.0, 14.0, -32.0], "target": [0.0, 4.0, 60.0], "up": [0.0, 1.0, 0.0], "fov": 40.0},
    "render": {"width": 896, "height": 448, "spp": 1, "mode": "full", "accel": "bvh", "shadows": True,
               "indirect": 1.0, "key": 0.18},
}
# One instance per line keeps the file short and diffs readable.
text = json.dumps(dict(scene, instances=["@"]), indent=1)
lines = ",\n".join("  " + json.dumps(i) for i in instances)
text = text.replace('[\n  "@"\n ]', "[\n" + lines + "\n ]")
with open("default_forest.sylva.json", "w") as f:
    f.write(text + "\n")
total = sum(s[3] * s[5] for s in SPECIES)
print(f"{len(instances)} instances, {total} instanced triangles (grower: target or one less)")
