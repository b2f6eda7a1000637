"""Shared pieces of the biaxial studies (scripts/biaxial_study.py, scripts/tradeoff_study.py).

A biaxial sample of N polydisperse disks (radii 4-6 mm, drop-and-roll deposit) in a box
of walls, no gravity: isotropic compaction at 10 kPa by force-driven walls for
T_COMPACT seconds, then the top wall moves down at V_TOP under constant lateral force.
The geometry scales with N from examples/scenes/biaxial.toml (2000 disks, 0.4 m wide).
"""
import csv
import math
import os
import resource
import subprocess
import time

T_COMPACT = 0.3
V_TOP = 0.05
PRESSURE = 1.0e4
H_STEP = 5e-4


def biaxial_scene(n, eps1_max, tol=1e-3, norm="Quad", max_sweeps=1000, decomposition=None, compact_only=False, ordering="stored",
                  method="nlgs"):
    """TOML text of the biaxial test of n disks loaded to eps1_max (compact_only: the
    compaction phase alone, T_COMPACT seconds, whose final.json restarts the loading)."""
    scale = math.sqrt(n / 2000.0)
    width = 0.4 * scale
    height = 0.535 * scale  # deposit height for the same aspect ratio
    h0 = 0.52 * scale  # compacted height, for the lateral force
    duration = T_COMPACT if compact_only else T_COMPACT + eps1_max * h0 / V_TOP + 0.01
    t = 0.02
    # the default order writes no line (so that cached runs keep their key)
    order_line = "" if ordering == "stored" else f'ordering = "{ordering}"'
    if method != "nlgs":
        order_line += f'\nmethod = "{method}"'
    dec = ""
    if decomposition:
        dec = "[decomposition]\n" + "".join(f"{k} = {v!r}\n".replace("'", '"') for k, v in decomposition.items())
    return f"""
gravity = [0.0, 0.0]
[time]
step = {H_STEP}
theta = 0.5
duration = {duration:.6f}
[solver]
tolerance = {tol}
norm = "{norm}"
max_sweeps = {max_sweeps}
check_every = 10
{order_line}
[detection]
alert = 5e-4
[output]
every = 0
vtk = false
box = {{ left = "left", right = "right", bottom = "bottom", top = "top", strain_from = {T_COMPACT} }}
{dec}
[[materials]]
name = "grain"
density = 2600.0
[[materials]]
name = "wall_h"
density = 2600.0
[[materials]]
name = "wall_v"
density = 2600.0
[[laws]]
materials = ["grain", "grain"]
friction = 0.5
[[laws]]
materials = ["grain", "wall_h"]
law = "frictionless"
[[laws]]
materials = ["grain", "wall_v"]
law = "frictionless"
[[laws]]
materials = ["wall_h", "wall_v"]
law = "none"
[[laws]]
materials = ["wall_h", "wall_h"]
law = "none"
[[laws]]
materials = ["wall_v", "wall_v"]
law = "none"
[[bodies]]
name = "bottom"
shape = "wall"
material = "wall_h"
position = [{width / 2}, {-t / 2}]
length = {width + 0.1 * scale}
thickness = {t}
fixed = true
[[bodies]]
name = "top"
shape = "wall"
material = "wall_h"
position = [{width / 2}, {height + 0.015}]
length = {width + 0.1 * scale}
thickness = {t}
drive.x = {{ velocity = 0.0 }}
drive.rot = {{ velocity = 0.0 }}
drive.y = [ {{ force = {{ ramp = [0.0, 0.0, 0.1, {-PRESSURE * width}] }}, until = {T_COMPACT} }}, {{ velocity = {-V_TOP} }} ]
[[bodies]]
name = "left"
shape = "wall"
material = "wall_v"
position = [{-t / 2}, {height / 2}]
rotation = 1.5707963267948966
length = {height + 0.1 * scale}
thickness = {t}
fixed = true
[[bodies]]
name = "right"
shape = "wall"
material = "wall_v"
position = [{width + t / 2}, {height / 2}]
rotation = 1.5707963267948966
length = {height + 0.1 * scale}
thickness = {t}
drive.y = {{ velocity = 0.0 }}
drive.rot = {{ velocity = 0.0 }}
drive.x = {{ force = {{ ramp = [0.0, 0.0, 0.1, {-PRESSURE * h0}] }} }}
[[generate]]
kind = "disk_deposit"
material = "grain"
count = {n}
radius_min = 0.004
radius_max = 0.006
box = [0.0, 0.0, {width}, {height}]
seed = 7
"""


def _num(v):
    try:
        return float(v)
    except ValueError:
        return v  # text columns (e.g. `prevailing`)


def run(nscdd, scene_text, out_dir, extra_args=(), cpu=False):
    """Runs a scene (or reuses the run already in out_dir for the same scene and
    arguments); returns (seconds, rows of history.csv as dicts): wall-clock seconds,
    or with cpu=True the CPU seconds of the run (user + system; for one-thread runs,
    unaffected by other work on the machine)."""
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, "scene.toml")
    stamp = os.path.join(out_dir, "elapsed.txt")
    key = scene_text + "\n# args: " + " ".join(extra_args)
    cached = os.path.exists(stamp) and os.path.exists(path + ".key") and open(path + ".key").read() == key
    if not cached:
        with open(path, "w") as f:
            f.write(scene_text)
        t0 = time.time()
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([nscdd, "run", path, "--out", out_dir, "--quiet", *extra_args], check=True)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        with open(stamp, "w") as f:
            f.write(f"{time.time() - t0}\n{(r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)}\n")
        with open(path + ".key", "w") as f:
            f.write(key)
    times = open(stamp).read().split()
    elapsed = float(times[1] if cpu and len(times) > 1 else times[0])
    with open(os.path.join(out_dir, "history.csv")) as f:
        rows = [{k: _num(v) for k, v in r.items()} for r in csv.DictReader(f)]
    return elapsed, rows


def loading(rows):
    """The rows of the loading phase (eps1 > 0)."""
    return [r for r in rows if r["time"] > T_COMPACT + 1e-9]


def smooth(xs, width):
    """Centred moving average (the wall forces fluctuate from step to step)."""
    out = []
    for i in range(len(xs)):
        a, b = max(0, i - width), min(len(xs), i + width + 1)
        out.append(sum(xs[a:b]) / (b - a))
    return out


def curve(rows, key, width=25):
    """(eps1, smoothed value) over the loading phase."""
    rr = loading(rows)
    return [r["eps1"] for r in rr], smooth([r[key] for r in rr], width)


def deviation(ref, other, npts=50):
    """RMS and max |difference| of two curves (x, y) on a common grid of x."""
    (x0, y0), (x1, y1) = ref, other
    if not x0 or not x1:
        return float("nan"), float("nan")
    lo, hi = max(x0[0], x1[0]), min(x0[-1], x1[-1])
    if hi <= lo:
        return float("nan"), float("nan")

    def interp(xs, ys, x):
        k = 0
        while k + 1 < len(xs) and xs[k + 1] < x:
            k += 1
        if k + 1 >= len(xs):
            return ys[-1]
        a, b = xs[k], xs[k + 1]
        return ys[k] if b == a else ys[k] + (ys[k + 1] - ys[k]) * (x - a) / (b - a)

    grid = [lo + (hi - lo) * i / (npts - 1) for i in range(npts)]
    d = [interp(x1, y1, x) - interp(x0, y0, x) for x in grid]
    return math.sqrt(sum(v * v for v in d) / len(d)), max(abs(v) for v in d)
