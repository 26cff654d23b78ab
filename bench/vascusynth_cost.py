#!/usr/bin/env python3
"""VascuSynth mode against VascuSynth's own cost.

Grows examples/vascusynth_like.toml (VascuSynth's 100^3 rods example, 1000 terminals) for seeds
1..S with the given extra [tree] keys and prints the cost sum(l r^2) in mm^3 (VascuSynth reaches
171.9 on these parameters), the segments shorter than 2r, and the intersecting pairs.

  /usr/bin/python3 bench/vascusynth_cost.py build/angiosynth 20 ['min_length_ratio = 0\\nrelax_sweeps = 0']
"""
import csv, json, os, statistics, subprocess, sys, tempfile

exe, seeds = sys.argv[1], int(sys.argv[2])
extra = sys.argv[3].replace("\\n", "\n") if len(sys.argv) > 3 else ""
root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
src = open(os.path.join(root, "examples", "vascusynth_like.toml")).read()
work = tempfile.mkdtemp()
costs, shorts, pairs = [], [], []
for seed in range(1, seeds + 1):
    text = src.replace("seed = 1", f"seed = {seed}", 1).replace("[tree]", "[tree]\n" + extra, 1)
    text = text.replace('"../demand_maps/', '"' + os.path.join(root, "demand_maps") + "/")
    toml = os.path.join(work, "v.toml")
    open(toml, "w").write(text)
    out = os.path.join(work, f"out{seed}")
    subprocess.run([exe, "generate", toml, "--out", out, "--quiet", "--no-image"], check=True)
    edges = list(csv.DictReader(open(os.path.join(out, "edges.csv"))))
    costs.append(sum(float(e["length"]) * float(e["radius"]) ** 2 for e in edges))
    shorts.append(sum(float(e["length"]) < 2 * float(e["radius"]) for e in edges))
    pairs.append(json.load(open(os.path.join(out, "sample.json")))["statistics"]["intersecting_pairs"])
print(f"cost mean {statistics.mean(costs):.1f} sd {statistics.stdev(costs) if seeds > 1 else 0:.1f} mm^3 (VascuSynth 171.9)")
print("costs", [round(c, 1) for c in costs])
print("segments shorter than 2r", shorts)
print("intersecting pairs", pairs)
