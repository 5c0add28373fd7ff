#!/usr/bin/env python3
"""Smoothly warped copies of SHREC meshes, to measure a collection of N = 8 of
one category where the data holds four (issue 19; docs/collections.md,
"Eight shapes of one category").

    bench/warped_copies.py --seed S --out DIR A.obj B.obj ...

For each input NAME.obj writes DIR/NAME_w.obj: every vertex moved by a
seeded, smooth, non-isometric map of space, x' = x S + a sum_k sin(x.w_k +
p_k) d_k (S a diagonal stretch of 0.85-1.15 per axis, three sine waves of
one to two periods across the shape, amplitude a = 6% of its radius), the
faces unchanged (vertex normals dropped: jsatlas takes the faces'). NAME.vts
beside NAME.obj is copied to DIR/NAME_w.vts with its coordinates moved the
same way, so line k is still the same keypoint (the vertex index first).
"""
import argparse
import math
import os
import random

parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
parser.add_argument("--seed", type=int, default=1)
parser.add_argument("--out", required=True)
parser.add_argument("meshes", nargs="+")
args = parser.parse_args()
os.makedirs(args.out, exist_ok=True)


def unit(rng):
    while True:
        v = [rng.gauss(0, 1) for _ in range(3)]
        n = math.sqrt(sum(x * x for x in v))
        if n > 1e-6:
            return [x / n for x in v]


for index, path in enumerate(args.meshes):
    rng = random.Random(args.seed * 1000 + index)
    lines = open(path).read().splitlines()
    verts = [tuple(float(x) for x in l.split()[1:4]) for l in lines if l.startswith("v ")]
    if not verts:
        raise SystemExit(f"{path}: no vertices")
    centre = [sum(v[a] for v in verts) / len(verts) for a in range(3)]
    radius = max(math.dist(v, centre) for v in verts)
    stretch = [rng.uniform(0.85, 1.15) for _ in range(3)]
    waves = []
    for _ in range(3):
        periods = rng.uniform(1.0, 2.0)  # across the shape's diameter
        w = [c * math.pi * periods / radius for c in unit(rng)]
        waves.append((w, rng.uniform(0, 2 * math.pi), unit(rng)))
    amplitude = 0.06 * radius

    def warp(p):
        x = [p[a] - centre[a] for a in range(3)]
        out = [centre[a] + x[a] * stretch[a] for a in range(3)]
        for w, phase, d in waves:
            s = amplitude * math.sin(sum(w[a] * x[a] for a in range(3)) + phase)
            for a in range(3):
                out[a] += s * d[a]
        return out

    stem = os.path.splitext(os.path.basename(path))[0]
    with open(os.path.join(args.out, stem + "_w.obj"), "w") as f:
        for l in lines:
            if l.startswith("v "):
                f.write("v %.6f %.6f %.6f\n" % tuple(warp([float(x) for x in l.split()[1:4]])))
            elif l.startswith("f "):
                f.write("f " + " ".join(t.split("/")[0] for t in l.split()[1:]) + "\n")
    vts = os.path.splitext(path)[0] + ".vts"
    if os.path.exists(vts):
        with open(os.path.join(args.out, stem + "_w.vts"), "w") as f:
            for l in open(vts):
                t = l.split()
                if len(t) >= 4:
                    f.write("%s %.6f %.6f %.6f\n" % ((t[0],) + tuple(warp([float(x) for x in t[1:4]]))))
    print(f"{path} -> {stem}_w.obj (stretch {stretch[0]:.3f} {stretch[1]:.3f} {stretch[2]:.3f})")
