#!/usr/bin/env python3
"""How deep the footing's settlement reaches: the grains' vertical displacement under
the footing against depth, in runs of scripts/continuum_footing.py (docs/CONTINUUM.md).

Usage: footing_profile.py RUN_DIR... [--at MM]

For each run (a directory with history.csv and vtk/bodies_*.vtp, written every 50
steps as the footing scenes do), takes the frame at or after the footing's first
contact and the first frame at least MM (default 40) mm of penetration later; the
grains then within the footing's width (|x − 0.5| < 0.1) are binned by their depth
below the footing's base at first contact (0.1 m bins), and the script prints each
bin's mean downward displacement in mm, the solid fraction of each bin
(|x − 0.5| < 0.4) at first contact, and the layer's σxx/σyy at rest (the frame
before first contact, 0.05–0.45 m below the base, from the contacts' normal forces
and branch vectors). Runs whose names share a prefix before `_s`
(hybt3_s3, hybt3_s5, ...) are also averaged. Reads the VTK files itself (binary,
base64, UInt64 headers, as nscdd writes them).
"""
import base64
import csv
import os
import re
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from continuum_footing import mean_se  # noqa: E402

HALF, WIDE, EVERY, BIN = 0.1, 0.4, 50, 0.1


def arrays(path):
    """{name: list of floats} of a .vtp file nscdd wrote."""
    text = open(path).read()
    out = {}
    for m in re.finditer(r'<DataArray type="Float64" Name="(\w+)"[^>]*format="binary"[^>]*>([^<]*)<', text):
        raw = base64.b64decode(m.group(2).strip())
        n = struct.unpack("<Q", raw[:8])[0] // 8
        out[m.group(1)] = struct.unpack(f"<{n}d", raw[8 : 8 + 8 * n])
    return out


def lateral_ratio(path, base):
    """σxx/σyy of the grains 0.05–0.45 m below `base` within |x − 0.5| < WIDE, from a
    contacts frame: Σ f_n l_x²/|l| over Σ f_n l_y²/|l| (l the branch between the two
    centres, 0.016–0.024 m for two grains; a wall's contact line runs from a grain's
    centre to the contact point, at most 0.012 m: left out; the normal part of the
    fabric stress)."""
    a = arrays(path)
    pts, fn = a["Points"], a["f_n"]
    sxx = syy = 0.0
    for k in range(len(fn)):
        x1, y1, x2, y2 = pts[6 * k], pts[6 * k + 1], pts[6 * k + 3], pts[6 * k + 4]
        lx, ly = x2 - x1, y2 - y1
        length = (lx * lx + ly * ly) ** 0.5
        if abs((x1 + x2) / 2 - 0.5) < WIDE and 0.05 < base - (y1 + y2) / 2 < 0.45 and 0.014 < length < 0.03:
            sxx += fn[k] * lx * lx / length
            syy += fn[k] * ly * ly / length
    return sxx / syy


def grains(path):
    """[(id, x, y, radius)] of the disks (radius < 0.015: not the walls) of a frame."""
    a = arrays(path)
    pts = a["Points"]
    return [(int(a["id"][i]), pts[3 * i], pts[3 * i + 1], a["radius"][i]) for i in range(len(a["id"])) if a["radius"][i] < 0.015]


def profile(run, at):
    r = list(csv.DictReader(open(os.path.join(run, "history.csv"))))
    fy = [float(x["footing_fy"]) for x in r]
    y = [float(x["footing_y"]) for x in r]
    first = next((i for i, f in enumerate(fy) if f > 1), None)
    if first is None:
        return None
    f0 = -(-int(float(r[first]["step"])) // EVERY)
    step = lambda f: min(len(r) - 1, f * EVERY - int(float(r[0]["step"])))
    f1 = next((f for f in range(f0, 10**6) if step(f) == len(r) - 1 or (y[step(f0)] - y[step(f)]) * 1000 >= at), None)
    if (y[step(f0)] - y[step(f1)]) * 1000 < at:
        return None
    base = y[step(f0)] - 0.02  # the footing's base (thickness 0.04)
    g0 = grains(os.path.join(run, "vtk", f"bodies_{f0:06d}.vtp"))
    p1 = {i: yy for i, x, yy, _ in grains(os.path.join(run, "vtk", f"bodies_{f1:06d}.vtp"))}
    bins, area = {}, {}
    for i, x, yy, rad in g0:
        if abs(x - 0.5) < HALF and i in p1 and yy < base:
            bins.setdefault(int((base - yy) / BIN), []).append((yy - p1[i]) * 1000)
        if abs(x - 0.5) < WIDE and yy < base:
            k = int((base - yy) / BIN)
            area[k] = area.get(k, 0.0) + 3.141592653589793 * rad * rad
    fraction = {k: a / (2 * WIDE * BIN) for k, a in area.items()}
    k0 = lateral_ratio(os.path.join(run, "vtk", f"contacts_{max(0, f0 - 1):06d}.vtp"), base)
    return {k: sum(v) / len(v) for k, v in bins.items()}, fraction, k0


def main():
    at = float(sys.argv[sys.argv.index("--at") + 1]) if "--at" in sys.argv else 40.0
    runs = [a for i, a in enumerate(sys.argv[1:], 1) if not a.startswith("--") and sys.argv[i - 1] != "--at"]
    groups = {}
    for run in runs:
        p = profile(run, at)
        name = os.path.basename(run.rstrip("/"))
        if p is None:
            print(f"{name}: not {at:g} mm deep by the end")
            continue
        groups.setdefault(name.rsplit("_s", 1)[0], []).append(p)
        print(f"{name}: " + "  ".join(f"{k * BIN:.1f}-{(k + 1) * BIN:.1f} m: {v:5.1f}" for k, v in sorted(p[0].items())))
        print(f"{name} σxx/σyy at rest, 0.05-0.45 m: {p[2]:.3f}")
        print(f"{name} solid fraction: " + "  ".join(f"{k * BIN:.1f}-{(k + 1) * BIN:.1f} m: {v:.3f}" for k, v in sorted(p[1].items())))
    for g, ps in groups.items():
        for j, what in ((0, f"downward displacement in mm at {at:g} mm under the footing"), (1, "solid fraction at first contact, |x - 0.5| < 0.4")):
            keys = sorted({k for p in ps for k in p[j]})
            mean = {k: sum(p[j][k] for p in ps if k in p[j]) / sum(1 for p in ps if k in p[j]) for k in keys}
            print(f"mean of {len(ps)} {g} ({what}, by depth below the footing's base): "
                  + "  ".join(f"{k * BIN:.1f}-{(k + 1) * BIN:.1f}: {v:.3g}" for k, v in sorted(mean.items())))
        m, se = mean_se([p[2] for p in ps])
        print(f"mean of {len(ps)} {g}: σxx/σyy of the layer at rest (the frame before first contact, 0.05-0.45 m below the base) {m:.3f} +- {se:.3f}")


if __name__ == "__main__":
    main()
