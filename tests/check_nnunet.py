#!/usr/bin/python3
"""Checks a DatasetNNN_Name directory against the rules nnU-Net v2 applies to raw datasets
(nnunetv2.experiment_planning.verify_dataset_integrity): dataset.json keys, file names and
channel suffixes, one label per case, identical geometry of image and label, and label values
that are consecutive from 0 and declared in dataset.json. Prints each violation; exit 1 if any."""
import json, os, re, sys

import nibabel as nib
import numpy as np

d = sys.argv[1]
problems = []
ds = json.load(open(os.path.join(d, "dataset.json")))
for key in ("channel_names", "labels", "numTraining", "file_ending"):
    if key not in ds:
        problems.append(f"dataset.json lacks {key}")
ending = ds["file_ending"]
channels = sorted(int(k) for k in ds["channel_names"])
if channels != list(range(len(channels))):
    problems.append(f"channel keys not consecutive from 0: {channels}")
label_values = sorted(ds["labels"].values())
if label_values != list(range(len(label_values))) or ds["labels"].get("background") != 0:
    problems.append(f"labels must be consecutive from 0 with background 0: {ds['labels']}")
name_re = re.compile(r"^(.+)_(\d{4})" + re.escape(ending) + "$")
cases = {}
for f in sorted(os.listdir(os.path.join(d, "imagesTr"))):
    m = name_re.match(f)
    if not m:
        problems.append(f"imagesTr/{f}: not <case>_<4-digit channel>{ending}")
        continue
    cases.setdefault(m.group(1), []).append(int(m.group(2)))
labels = sorted(f[: -len(ending)] for f in os.listdir(os.path.join(d, "labelsTr")) if f.endswith(ending))
if sorted(cases) != labels:
    problems.append(f"cases with images and cases with labels differ: {sorted(set(cases) ^ set(labels))}")
if ds["numTraining"] != len(labels):
    problems.append(f"numTraining {ds['numTraining']} but {len(labels)} labels")
for case, chans in cases.items():
    if "." in case:
        problems.append(f"case id {case} holds a dot")
    if sorted(chans) != channels:
        problems.append(f"{case}: channels {sorted(chans)}, expected {channels}")
    lab = nib.load(os.path.join(d, "labelsTr", case + ending))
    values = np.unique(np.asarray(lab.dataobj))
    if not set(values.tolist()) <= set(label_values):
        problems.append(f"{case}: label values {values.tolist()} not in {label_values}")
    for c in chans:
        img = nib.load(os.path.join(d, "imagesTr", f"{case}_{c:04d}{ending}"))
        if img.shape != lab.shape:
            problems.append(f"{case}: image shape {img.shape} != label shape {lab.shape}")
        if not np.allclose(img.affine, lab.affine, atol=1e-6):
            problems.append(f"{case}: image and label affines differ")
        if not np.allclose(img.header.get_zooms(), lab.header.get_zooms()):
            problems.append(f"{case}: spacing differs")
for p in problems:
    print(p)
print(f"{len(cases)} cases checked, {len(problems)} problems")
sys.exit(1 if problems else 0)
