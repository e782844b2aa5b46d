#!/usr/bin/env python3
"""render.bounce_samples on its speed/accuracy front: whole samples against samples that share a few samples' bounced
light, on the `final` preset's lighting, every picture against the same settings at many whole samples (measured in
one run). The time at equal error is the whole samples' time scaled to the error the shared ones reach (the error
falling as 1/sqrt(samples), the time rising linearly, from the whole row of the same spp).

  PYTHONPATH=build/release/python python3 tests/bench/bench_bounce_samples.py --scene forest --reference 128
  PYTHONPATH=build/release/python python3 tests/bench/bench_bounce_samples.py --scene tree --reference 256

Ends with name=value lines: error and trace seconds of each configuration, and the whole samples' time at that error
over the configuration's time (speedup, > 1: the shared bounces pay)."""

import argparse
import time

import numpy as np

import sylva


def luminance(a):
    return a[..., 0] * 0.2126 + a[..., 1] * 0.7152 + a[..., 2] * 0.0722


def relative_l2(a, b):
    la, lb = luminance(a), luminance(b)
    return float(np.sqrt(((la - lb) ** 2).sum() / (lb ** 2).sum()))


def scene_of(name):
    if name == "tree":   # one grown broadleaf, seen whole
        s = sylva.Scene()
        s.add_species(grow={"species": "broadleaf", "triangles": 60000, "height": 10, "seed": 2}, grid=64)
        s.add_instances(0, np.array([[0.0, 0.0, 0.0]]))
        s.camera.position = (0.0, 4.0, -16.0)
        s.camera.target = (0.0, 5.0, 0.0)
        s.render.width, s.render.height = 240, 180
    else:                # the bundled default forest
        s = sylva.Scene.default()
        s.render.width, s.render.height = 320, 160
    s.apply_quality("final")
    s.sun.set_angles(40, 150)
    return s


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", choices=("tree", "forest"), default="forest")
    p.add_argument("--reference", type=int, default=128, help="whole samples of the reference picture")
    p.add_argument("--configs", default="4/0,4/1,16/0,16/4,16/2,64/0,64/16,64/8", help="SPP/BOUNCE_SAMPLES,... (0: all)")
    p.add_argument("--reps", type=int, default=3, help="renders per configuration (the median time)")
    p.add_argument("--cache", default=None, help="grid cache folder (default: the user's)")
    a = p.parse_args()
    base = scene_of(a.scene)
    ref_scene = base.copy()
    ref_scene.render.spp, ref_scene.render.bounce_samples = a.reference, 0   # whole samples, whatever the preset shares
    t = time.time()
    ref = sylva.render(ref_scene, cache=a.cache).linear.copy()
    print(f"{a.scene}: reference {a.reference} whole samples in {time.time() - t:.1f} s")
    rows = {}
    print("| spp | bounce samples | relative L2 of luminance | mean / reference | trace (s, median) |")
    print("| --- | --- | --- | --- | --- |")
    for c in a.configs.split(","):
        spp, bs = (int(v) for v in c.split("/"))
        x = base.copy()
        x.render.spp, x.render.bounce_samples = spp, bs
        times = []
        for _ in range(a.reps):
            r = sylva.render(x, cache=a.cache)
            times.append(r.timings["trace"])
        err, sec = relative_l2(r.linear, ref), float(np.median(times))
        rows[(spp, bs)] = (err, sec)
        print(f"| {spp} | {bs if bs else 'all'} | {err:.4f} | {luminance(r.linear).mean() / luminance(ref).mean():.4f} | {sec:.3f} |")
    for (spp, bs), (err, sec) in rows.items():
        print(f"{a.scene}_spp{spp}_bs{bs}_error={err:.4f}")
        print(f"{a.scene}_spp{spp}_bs{bs}_seconds={sec:.3f}")
        whole = rows.get((spp, 0))
        if bs and whole:
            # Whole samples reaching this error: spp x (e_whole / e)^2, at spp's time per sample.
            equal_time = whole[1] * (whole[0] / err) ** 2
            print(f"{a.scene}_spp{spp}_bs{bs}_speedup={equal_time / sec:.2f}")


if __name__ == "__main__":
    main()
