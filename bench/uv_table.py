#!/usr/bin/env python3
"""The markdown table of bench/uv_before_after.sh's reports: OUT SHAPE... (stdlib only)."""
import json
import os
import sys

out, shapes = sys.argv[1], sys.argv[2:]
print("| shape | map | flipped (area %) | overlap | stretch L2 | Linf | sym. Dirichlet "
      "| conformal | area dist. | seam length | charts | packing | s |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for s in shapes:
    for m, label in [("psi", "psi alone"), ("landed", "valid, landed"), ("now", "valid, this round")]:
        path = f"{out}/{s}_{m}_uv.json"
        if not os.path.exists(path):
            continue
        j = json.load(open(path))
        v = j.get("valid_uv", {})
        t = "%.2f" % v["seconds"] if v else "-"
        pk = "%.2f" % j["packing_efficiency"] if v else "-"
        print(f"| {s} | {label} | {j['flipped']} ({100 * j['flipped_area_fraction']:.2f}%) "
              f"| {j['overlap_ratio']:.3g} | {j['stretch_l2']:.3g} | {j['stretch_linf']:.3g} "
              f"| {j['symmetric_dirichlet']:.3g} | {j['conformal_distortion']:.3g} "
              f"| {j['area_distortion']:.3g} | {j['seam_length']:.3g} | {j['charts']} | {pk} | {t} |")
