#!/usr/bin/env python3
"""A reference point for eval-corr that learns nothing: each keypoint of shape I
goes to the nearest vertex of shape J, both in their stored poses and normalised
(vertex centroid at the origin, farthest vertex at distance 1); the error is the
distance to J's true keypoint. Mean over all ordered pairs, x 1e-2, the share
within 0.05, and the mean squared distance x 1e-2 (the other reading of the
paper's L2, as `jsatlas eval-corr` prints it). An atlas whose correspondences are no better than this has learned
nothing about the family beyond where its surfaces lie.

    bench/corr_trivial_baseline.py SHREC_DIR ant teddy
(reads SHREC_DIR/<category>_<k>.obj and .vts for every k present; plain Python)"""
import glob
import os
import sys


def load(obj, vts):
    verts = []
    with open(obj) as f:
        for line in f:
            t = line.split()
            if t and t[0] == "v":
                verts.append([float(x) for x in t[1:4]])
    with open(vts) as f:
        keys = [int(line.split()[0]) for line in f if line.strip()]
    c = [sum(v[i] for v in verts) / len(verts) for i in range(3)]
    verts = [[v[i] - c[i] for i in range(3)] for v in verts]
    r = max(sum(x * x for x in v) ** 0.5 for v in verts)
    return [[x / r for x in v] for v in verts], keys


def d2(a, b):
    return sum((a[i] - b[i]) ** 2 for i in range(3))


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    root = sys.argv[1]
    for cat in sys.argv[2:]:
        objs = sorted(glob.glob(os.path.join(root, cat + "_*.obj")))
        shapes = [load(o, o[:-4] + ".vts") for o in objs]
        errs = []
        for i, (vi, ki) in enumerate(shapes):
            for j, (vj, kj) in enumerate(shapes):
                if i == j:
                    continue
                for a, b in zip(ki, kj):
                    q = min(vj, key=lambda v: d2(v, vi[a]))
                    errs.append(d2(q, vj[b]) ** 0.5)
        within = sum(e < 0.05 for e in errs) / len(errs)
        squared = sum(e * e for e in errs) / len(errs)
        print(f"{cat}: {len(shapes)} shapes, {len(errs)} keypoint pairs: mean L2 x1e-2 = "
              f"{100 * sum(errs) / len(errs):.2f}, within 0.05 = {100 * within:.1f}%, "
              f"mean squared distance x1e-2 = {100 * squared:.2f}")


if __name__ == "__main__":
    main()
