#!/usr/bin/env python3
"""Midpoint subdivision of an OBJ mesh (each triangle into 4), LEVELS times, for
timing `jsatlas chart` on large meshes (issue 20; docs/uv-quality.md, "Time").
With --sphere the new vertices are pushed out to the mean radius (a finer sphere).

    bench/subdivide_mesh.py IN.obj OUT.obj LEVELS [--sphere]
"""
import math
import os
import sys

if len(sys.argv) < 4:
    sys.exit("usage: subdivide_mesh.py IN.obj OUT.obj LEVELS [--sphere]")
src, dst, levels = sys.argv[1], sys.argv[2], int(sys.argv[3])
sphere = "--sphere" in sys.argv[4:]
v, f = [], []
for line in open(src):
    t = line.split()
    if not t:
        continue
    if t[0] == "v":
        v.append(tuple(float(x) for x in t[1:4]))
    elif t[0] == "f":
        f.append(tuple(int(x.split("/")[0]) - 1 for x in t[1:4]))
radius = sum(math.sqrt(x * x + y * y + z * z) for x, y, z in v) / len(v)
for _ in range(levels):
    mid, out = {}, []

    def middle(a, b):
        key = (min(a, b), max(a, b))
        if key not in mid:
            p = tuple((v[a][k] + v[b][k]) / 2 for k in range(3))
            if sphere:
                r = math.sqrt(sum(c * c for c in p))
                p = tuple(c * radius / r for c in p)
            mid[key] = len(v)
            v.append(p)
        return mid[key]

    for a, b, c in f:
        ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
        out += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    f = out
with open(dst + ".tmp", "w") as o:
    o.writelines("v %.9g %.9g %.9g\n" % p for p in v)
    o.writelines("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in f)
os.replace(dst + ".tmp", dst)
print("%s: %d vertices, %d faces" % (dst, len(v), len(f)))
