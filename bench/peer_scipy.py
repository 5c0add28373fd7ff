#!/usr/bin/python3
"""The SciPy peer of bench_kernels, on the same inputs (bench_kernels --dump DIR):

  Chamfer (6D and 2D)  scipy.spatial.cKDTree, both directions, both tree builds
                       included, queries with `workers` threads; the same value
                       as ours (squared distances, mean each way, summed)
  assignment           scipy.optimize.linear_sum_assignment on the same cost
                       matrix; the same optimal cost as our LAPJV

  /usr/bin/python3 bench/peer_scipy.py DIR [--workers 2] [--runs 5] [--json FILE]

Each peer's value is checked against ours (DIR/ours.txt) before its time is
reported; the medians are printed next to ours with the ratio. cKDTree is timed
with its default tree and with balanced_tree=False (a cheaper build), and the
faster of the two is the one compared.
"""
import argparse
import json
import os
import statistics
import sys
import time

import numpy as np
import scipy
from scipy.optimize import linear_sum_assignment
from scipy.spatial import cKDTree


def read_matrix(path):
    """int64 rows, int64 cols, then rows x cols float64 row-major, little-endian."""
    with open(path, "rb") as f:
        raw = f.read()
    rows, cols = (int(v) for v in np.frombuffer(raw[:16], dtype="<i8"))
    data = np.frombuffer(raw[16:], dtype="<f8")
    if data.size != rows * cols:
        raise SystemExit(f"{path}: header says {rows} x {cols}, file holds {data.size} values")
    return data.reshape(rows, cols)


def read_ours(path):
    out = {}
    with open(path) as f:
        for line in f:
            name, value = line.split()
            out[name] = float(value)
    return out


def median_seconds(runs, f):
    f()  # warm-up
    t = []
    for _ in range(runs):
        t0 = time.perf_counter()
        f()
        t.append(time.perf_counter() - t0)
    return statistics.median(t)


def chamfer(x, y, workers, **tree_options):
    """mean_i min_j |x_i - y_j|^2 + mean_j min_i |y_j - x_i|^2, trees built here."""
    dx, _ = cKDTree(y, **tree_options).query(x, k=1, workers=workers)
    dy, _ = cKDTree(x, **tree_options).query(y, k=1, workers=workers)
    return float(np.mean(dx * dx) + np.mean(dy * dy))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("dir", help="the directory written by bench_kernels --dump")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--json", help="append one JSON line per kernel to this file")
    a = p.parse_args()
    ours = read_ours(os.path.join(a.dir, "ours.txt"))
    print(f"scipy {scipy.__version__}, numpy {np.__version__}; cKDTree workers={a.workers}, "
          f"median of {a.runs} after a warm-up; ours on {int(ours['threads'])} threads")
    records, failed = [], False

    for name in ("chamfer6", "chamfer2"):
        x = read_matrix(os.path.join(a.dir, name + "_x.bin"))
        y = read_matrix(os.path.join(a.dir, name + "_y.bin"))
        value = chamfer(x, y, a.workers)
        rel = abs(value - ours[name + "_value"]) / ours[name + "_value"]
        ok = rel < 1e-5  # ours searches in float, scipy in double
        failed |= not ok
        variants = {}
        for label, opts in (("default", {}), ("balanced_tree=False", {"balanced_tree": False})):
            variants[label] = median_seconds(a.runs, lambda: chamfer(x, y, a.workers, **opts))
        best = min(variants, key=variants.get)
        s = variants[best]
        print(f"{name:10s} {x.shape[0]} x {y.shape[0]} {x.shape[1]}D: CD ours {ours[name + '_value']:.9g} "
              f"scipy {value:.9g} (rel diff {rel:.1e}) {'same' if ok else 'DIFFERENT'}")
        print(f"{'':10s} ours {ours[name + '_s']:.4f} s, scipy cKDTree {s:.4f} s ({best}; "
              + ", ".join(f"{k} {v:.4f} s" for k, v in variants.items())
              + f"): ours/scipy = {ours[name + '_s'] / s:.3f}")
        records.append(dict(peer="scipy", kernel=name, size=f"{x.shape[0]} x {y.shape[0]} {x.shape[1]}D",
                            value=value, ours_value=ours[name + "_value"], same=ok,
                            median_s=s, variant=best, variants_s=variants,
                            ours_s=ours[name + "_s"], workers=a.workers))

    cost = read_matrix(os.path.join(a.dir, "assignment_cost.bin"))
    rows, cols = linear_sum_assignment(cost)
    total = float(cost[rows, cols].sum())
    rel = abs(total - ours["assignment_cost"]) / ours["assignment_cost"]
    ok = rel < 1e-9
    failed |= not ok
    s = median_seconds(a.runs, lambda: linear_sum_assignment(cost))
    print(f"assignment {cost.shape[0]} x {cost.shape[1]}: cost ours {ours['assignment_cost']:.12g} "
          f"scipy {total:.12g} (rel diff {rel:.1e}) {'same' if ok else 'DIFFERENT'}")
    print(f"{'':10s} ours {ours['assignment_s']:.4f} s, scipy linear_sum_assignment {s:.4f} s: "
          f"ours/scipy = {ours['assignment_s'] / s:.3f}")
    records.append(dict(peer="scipy", kernel="assignment", size=f"{cost.shape[0]} x {cost.shape[1]}",
                        value=total, ours_value=ours["assignment_cost"], same=ok, median_s=s,
                        ours_s=ours["assignment_s"]))

    if a.json:
        with open(a.json, "a") as f:
            for r in records:
                f.write(json.dumps(r) + "\n")
    if failed:
        print("peer_scipy: a peer value differs from ours", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
