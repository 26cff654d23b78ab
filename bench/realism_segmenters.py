#!/usr/bin/python3
"""How much harder each effect group and each modality profile makes vessel segmentation for
two classical segmenters with fixed rules: a robust threshold on the image (median + 3 × 1.4826 ×
median absolute deviation, the background's mean + 3σ when the background dominates), and
scikit-image's Frangi vesselness (sigmas 0.5-3 voxels, bright vessels, on the image scaled to its
0.5th-99.95th percentiles) above 2 % of its maximum. Every image is
grown from examples/vascusynth_like.toml; the scores are computed here with NumPy from the
sample's exact labels (mask, centreline, radius, instances, distractors, edges.csv), so nothing
of angiosynth's own scoring is used.

Usage: /usr/bin/python3 bench/realism_segmenters.py BUILD_DIR [SEEDS]   (prints a Markdown table)
"""
import csv
import os
import subprocess
import sys
import tempfile

import nibabel as nib
import numpy as np
from skimage.filters import frangi

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LEVELS = 'background = 40\nvessel = 300\ndtype = "float32"\n'
NOISE = '[[effect]]\ntype = "gaussian"\nsigma = 20\n'
# Each group on top of the same plain image with the same noise, so that the rows differ by the
# group only.
GROUPS = {
    "plain (noise σ = 20)": "",
    "decoys": '[[effect]]\ntype = "decoys"\nblobs = 12\ntubes = 8\nplates = 4\n',
    "bone + calcification": '[[effect]]\ntype = "bone"\ncount = 1\ncortex = "4 contrast"\nmarrow = "0.8 contrast"\n'
                            '[[effect]]\ntype = "calcification"\ncount = 8\n',
    "tissue (compartments, cells, texture)": '[[effect]]\ntype = "compartments"\ncontrast = "0.15 contrast"\n'
                                             '[[effect]]\ntype = "voronoi"\namplitude = "0.08 contrast"\nwall = "0.1 contrast"\n'
                                             '[[effect]]\ntype = "texture"\namplitude = "0.08 contrast"\n',
    "inflow saturation": '[[effect]]\ntype = "inflow"\nlength = "30 mm"\nfloor = 0.1\n',
    "slab steps": '[[effect]]\ntype = "slab"\nthickness = "10 mm"\ndrop = 0.35\n',
    "k-space (Gibbs, ghosts, spike)": '[[effect]]\ntype = "gibbs"\nkeep_x = 0.6\nkeep_y = 0.6\nkeep_z = 0.6\n'
                                      '[[effect]]\ntype = "motion_ghost"\nperiod = 8\namplitude = 0.3\n'
                                      '[[effect]]\ntype = "kspace_spike"\nkx = 9\nky = 5\namplitude = 0.01\n',
    "OCTA tails and shadows": '[[effect]]\ntype = "projection"\ntail = 0.4\ntail_length = "6 voxel"\nshadow_length = "8 voxel"\n',
}
PROFILES = ["cta", "tof_mra", "two_photon", "octa", "domain_randomisation"]


def segment(image):
    a = image.astype(np.float32)
    median = np.median(a)
    threshold = a > median + 3 * 1.4826 * np.median(np.abs(a - median))
    lo, hi = np.percentile(a, [0.5, 99.95])
    v = frangi((a - lo) / max(hi - lo, 1e-6), sigmas=[0.5, 1, 1.5, 2, 3], black_ridges=False)
    return {"threshold": threshold, "Frangi": v > 0.02 * v.max()}


def depth_of_segments(sample):
    parent = {}
    with open(os.path.join(sample, "edges.csv")) as f:
        for row in csv.DictReader(f):
            parent[int(row["node2id"])] = int(row["node1id"])
    depth = {}

    def d(n):
        if n not in depth:
            depth[n] = 0 if n not in parent else d(parent[n]) + 1
        return depth[n]

    sys.setrecursionlimit(100000)
    return {s: d(s) for s in parent}


def scores(pred, sample):
    load = lambda n: np.asanyarray(nib.load(os.path.join(sample, n)).dataobj)
    mask, cl, radius, inst = load("mask.nii.gz") > 0, load("centerline.nii.gz") > 0, load("radius.nii.gz"), load("instances.nii.gz")
    tp = np.logical_and(pred, mask).sum()
    out = {"dice": 2 * tp / max(pred.sum() + mask.sum(), 1), "precision": tp / max(pred.sum(), 1), "recall": tp / max(mask.sum(), 1)}
    dist = [f for f in os.listdir(sample) if f.startswith("distractors_")]
    if dist:
        dm = load(dist[0]) > 0
        out["distractor_fp"] = np.logical_and(pred, dm).sum() / max(dm.sum(), 1)
    h = float(nib.load(os.path.join(sample, "mask.nii.gz")).header.get_zooms()[0])
    r = radius[cl]
    hit = pred[cl]
    out["recall_thin"] = hit[r < h].mean() if (r < h).any() else float("nan")
    out["recall_thick"] = hit[r >= 2 * h].mean() if (r >= 2 * h).any() else float("nan")
    depth = depth_of_segments(sample)
    levels = np.array([depth.get(int(s), 0) for s in inst[cl]])
    deep = levels >= np.percentile(levels, 75)
    out["recall_distal"] = hit[deep].mean()
    out["recall_proximal"] = hit[levels <= np.percentile(levels, 25)].mean()
    return out


def main():
    build = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "build")
    seeds = [int(s) for s in (sys.argv[2] if len(sys.argv) > 2 else "1,2").split(",")]
    rows = []
    with tempfile.TemporaryDirectory() as work:
        conditions = []
        for name, body in GROUPS.items():
            path = os.path.join(work, f"group{len(conditions)}.toml")
            with open(path, "w") as f:
                f.write(LEVELS + body + NOISE)
            conditions.append((name, path))
        conditions += [(f"profile `{p}`", p) for p in PROFILES]
        for name, profile in conditions:
            acc = {}
            for seed in seeds:
                out = os.path.join(work, "sample")
                subprocess.run([os.path.join(build, "angiosynth"), "generate", os.path.join(ROOT, "examples/vascusynth_like.toml"), "--out", out,
                                "--force", "--quiet", "--seed", str(seed), "--profile", profile, "--format", "nifti"], check=True)
                stem = os.path.splitext(os.path.basename(profile))[0]
                image = np.asanyarray(nib.load(os.path.join(out, f"image_{stem}.nii.gz")).dataobj)
                for method, pred in segment(image).items():
                    for k, v in scores(pred, out).items():
                        acc.setdefault((method, k), []).append(v)
            rows.append((name, {k: float(np.nanmean(v)) for k, v in acc.items()}))
            print(f"{name}: done", file=sys.stderr)
    cols = [("dice", "Dice"), ("precision", "precision"), ("recall", "recall"), ("recall_thick", "recall r ≥ 2 voxels"),
            ("recall_thin", "recall r < 1 voxel"), ("recall_proximal", "recall, first quartile of levels"),
            ("recall_distal", "recall, last quartile of levels"), ("distractor_fp", "distractor voxels called vessel")]
    for method in ["threshold", "Frangi"]:
        print(f"\n**{method}** (mean over `--seed` {', '.join(map(str, seeds))})\n")
        print("| image | " + " | ".join(c[1] for c in cols) + " |")
        print("|---" * (len(cols) + 1) + "|")
        for name, r in rows:
            cells = [f"{r[(method, k)]:.3f}" if (method, k) in r else "" for k, _ in cols]
            print(f"| {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
