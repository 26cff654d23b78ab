#!/usr/bin/env python3
"""CCO trees in OpenCCO's own set-up, to compare with OpenCCO's.

A 20,000 mm^3 ball, OpenCCO's constants (13300 Pa, 7980 Pa beyond 250 terminals, 8330 mm^3/s,
3.6 mPa*s), seeds 1..S. Prints the total volume sum(pi r^2 l) (mean, sd, each seed), the
terminal spacing (nearest-neighbour distance: minimum and median), segments not longer than 2r,
intersecting pairs and the wall time per tree. OpenCCO's trees carry 289-293 mm^3 at 1000
terminals and 352.9 at 4000 (its geometry, radii solved with these physics).

  /usr/bin/python3 bench/cco_opencco_ball.py build/angiosynth 1000 10 [EXTRA_TREE_KEYS]
  e.g. EXTRA_TREE_KEYS='spacing_from = "segments"\\nbifurcation = "kamiya"' for the old reading
"""
import csv, json, math, os, statistics, subprocess, sys, tempfile, time

import numpy as np
from scipy.spatial import cKDTree

exe, n, seeds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
extra = sys.argv[4].replace("\\n", "\n") if len(sys.argv) > 4 else ""
radius = (3 * 20000 / (4 * math.pi)) ** (1 / 3)
work = tempfile.mkdtemp()
vols, rows_out = [], []
for seed in range(1, seeds + 1):
    toml = os.path.join(work, "ball.toml")
    with open(toml, "w") as f:
        f.write(f'seed = {seed}\n[domain]\nshape = "sphere"\nradius = "{radius:.6f} mm"\nvoxel_size = "0.3 mm"\n'
                f'[tree]\nmethod = "cco"\nterminals = {n}\n{extra}\n'
                '[physics]\nmurray_exponent = 3\nviscosity = "3.6 mPa*s"\nperfusion_pressure = "13300 Pa"\n'
                f'terminal_pressure = "{7980 if n > 250 else 8400} Pa"\nperfusion_flow = "8330 mm3/s"\n')
    out = os.path.join(work, f"out{seed}")
    t0 = time.time()
    subprocess.run([exe, "generate", toml, "--out", out, "--quiet", "--no-image"], check=True)
    wall = time.time() - t0
    edges = list(csv.DictReader(open(os.path.join(out, "edges.csv"))))
    L = np.array([float(e["length"]) for e in edges])
    R = np.array([float(e["radius"]) for e in edges])
    vol = float(np.sum(math.pi * R * R * L))
    term = [k for k in csv.DictReader(open(os.path.join(out, "keypoints.csv"))) if k["type"] == "terminal"]
    P = np.array([[float(k["x_mm"]), float(k["y_mm"]), float(k["z_mm"])] for k in term])
    d, _ = cKDTree(P).query(P, k=2)
    st = json.load(open(os.path.join(out, "sample.json")))["statistics"]
    vols.append(vol)
    rows_out.append((seed, vol, d[:, 1].min(), float(np.median(d[:, 1])), int(np.sum(L <= 2 * R)), st["intersecting_pairs"], wall))
print(f"{n} terminals, {seeds} seeds: volume {statistics.mean(vols):.1f} +- {statistics.stdev(vols) if seeds > 1 else 0:.1f} mm^3")
print("seed  volume  spacing_min  spacing_median  short  pairs  seconds")
for r in rows_out:
    print("%4d %7.1f %12.2f %15.2f %6d %6d %8.2f" % r)
