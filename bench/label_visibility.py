#!/usr/bin/python3
"""How many label voxels does the image show? For each label policy, makes a copy of a dataset
spec with [image] label_policy set, builds the dataset, and reports per case the fraction of
vessel-labelled voxels whose degraded intensity lies below background + 2 sigma, background and
sigma being the mean and standard deviation of the image over label-0 voxels (nibabel, numpy).

  /usr/bin/python3 bench/label_visibility.py build/angiosynth examples/dataset_small.toml /tmp/labvis
"""
import json, os, re, subprocess, sys

import nibabel as nib
import numpy as np

exe, spec, work = sys.argv[1], os.path.abspath(sys.argv[2]), sys.argv[3]
policies = sys.argv[4].split(",") if len(sys.argv) > 4 else ["binary", "threshold", "visible", "soft", "ignore"]
os.makedirs(work, exist_ok=True)
text = open(spec).read()
# Relative paths of the spec stay valid from the copy.
text = re.sub(r'"(\.\./[^"]+)"', lambda m: '"' + os.path.normpath(os.path.join(os.path.dirname(spec), m.group(1))) + '"', text)
for policy in policies:
    t = re.sub(r"^\[image\]\n", "[image]\nlabel_policy = \"%s\"\n" % policy, text, count=1, flags=re.M)
    if t == text:
        t = text + "\n[image]\nlabel_policy = \"%s\"\n" % policy
    copy = os.path.join(work, policy + ".toml")
    open(copy, "w").write(t)
    out = os.path.join(work, policy)
    subprocess.run(["rm", "-rf", out], check=True)
    subprocess.run([exe, "dataset", copy, "--out", out, "--quiet"], check=True)
    ds = os.path.join(out, os.listdir(out)[0])
    fractions, voxels, kept = [], [], []
    for lab in sorted(os.listdir(os.path.join(ds, "labelsTr"))):
        case = lab[: -len(".nii.gz")]
        l = np.asarray(nib.load(os.path.join(ds, "labelsTr", lab)).dataobj)
        img = np.asarray(nib.load(os.path.join(ds, "imagesTr", case + "_0000.nii.gz")).dataobj).astype(np.float64)
        vessel = (l >= 0.5) & (l < 1.5) if policy == "soft" else (l == 1)
        bg = img[l == 0]
        limit = bg.mean() + 2 * bg.std()
        fractions.append(float((img[vessel] < limit).mean()) if vessel.any() else float("nan"))
        voxels.append(int(vessel.sum()))
        sample = json.load(open(os.path.join(ds, "groundtruth", case + ".json")))["sample"]
        rec = sample["degradation"].get(sample["parameters"]["profiles"][0] if sample["parameters"]["profiles"] else "", {}).get("label") \
            or sample["statistics"]["label"]
        kept.append(rec["vessel"])
    f = np.array(fractions)
    print("%-9s label voxels below bg+2sd: %4.1f %% (cases %4.1f-%4.1f %%); vessel voxels per case %7.0f; centreline length kept %.3f"
          % (policy, 100 * np.nanmean(f), 100 * np.nanmin(f), 100 * np.nanmax(f), np.mean(voxels), np.mean(kept)))
