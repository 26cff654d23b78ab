#!/usr/bin/python3
"""A small 3D U-Net trained on samples made on the fly, scored on a held-out generated test set
beside a classical baseline (Frangi et al. 1998 vesselness, thresholded by Otsu's rule).

    /usr/bin/python3 examples/train_unet.py [--minutes 6] [--label-policy visible|binary] [--out out/train_unet]

Training samples: examples/dataset_train.toml through angiosynth.torch.SyntheticVessels (four 48^3
patches of each sample, one DataLoader worker generating while the main process trains), labelled
under the dataset default (visible: what the image shows) or with --label-policy binary the full
vessel mask. Test set: the 8 samples of examples/dataset_small.toml (same distribution, another
seed), whole 64^3 volumes. Both are scored with angiosynth.score against the full vessel mask,
and by Dice against the test set's visible-vessel labels. Writes OUT/results.json and
OUT/training.png (loss and held-out Dice against training time).
"""

import argparse
import json
import os
import pathlib
import sys
import time

import numpy as np
import torch
import torch.nn as nn

SOURCE = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(SOURCE / "build/python"))

import angiosynth  # noqa: E402
from angiosynth.torch import SyntheticVessels  # noqa: E402


def block(cin: int, cout: int) -> nn.Module:
    return nn.Sequential(
        nn.Conv3d(cin, cout, 3, padding=1), nn.InstanceNorm3d(cout, affine=True), nn.LeakyReLU(0.01, inplace=True),
        nn.Conv3d(cout, cout, 3, padding=1), nn.InstanceNorm3d(cout, affine=True), nn.LeakyReLU(0.01, inplace=True),
    )


class UNet3D(nn.Module):
    """Three resolution levels (8, 16, 32 channels), skip connections, one logit per voxel."""

    def __init__(self, width: int = 8):
        super().__init__()
        self.enc1, self.enc2, self.bottom = block(1, width), block(width, 2 * width), block(2 * width, 4 * width)
        self.pool = nn.MaxPool3d(2)
        self.up2, self.dec2 = nn.ConvTranspose3d(4 * width, 2 * width, 2, stride=2), block(4 * width, 2 * width)
        self.up1, self.dec1 = nn.ConvTranspose3d(2 * width, width, 2, stride=2), block(2 * width, width)
        self.head = nn.Conv3d(width, 1, 1)

    def forward(self, x):
        e1 = self.enc1(x)
        e2 = self.enc2(self.pool(e1))
        b = self.bottom(self.pool(e2))
        d2 = self.dec2(torch.cat([self.up2(b), e2], 1))
        d1 = self.dec1(torch.cat([self.up1(d2), e1], 1))
        return self.head(d1)


def normalise(image: torch.Tensor) -> torch.Tensor:
    """Per image: zero mean, unit variance (nnU-Net's rule for non-CT channels)."""
    dims = tuple(range(1, image.dim()))
    return (image - image.mean(dims, keepdim=True)) / (image.std(dims, keepdim=True) + 1e-6)


def loss_fn(logits, target):
    """Binary cross-entropy plus soft Dice, as nnU-Net combines them."""
    p = torch.sigmoid(logits)
    inter = (p * target).sum()
    dice = 1 - (2 * inter + 1) / (p.sum() + target.sum() + 1)
    return nn.functional.binary_cross_entropy_with_logits(logits, target) + dice


def headline(result: dict, prediction: np.ndarray, sample) -> dict:
    cal = [b for b in result["calibre"] if b["recall"] is not None]
    label = np.asarray(sample.label) > 0
    both = np.count_nonzero(prediction & label)
    return {
        "dice": result["overlap"]["dice"],
        "dice_visible_label": 2 * both / max(1, np.count_nonzero(prediction) + np.count_nonzero(label)),
        "cldice": result["cldice"]["exact_centreline"]["cldice"],
        "centreline_recall": result["centreline"]["recall"],
        "calibre_recall": {f"{b['radius_voxels'][0]}-{b['radius_voxels'][1]} vox": b["recall"] for b in cal},
    }


def mean_scores(rows: list) -> dict:
    out = {k: float(np.mean([r[k] for r in rows])) for k in ("dice", "dice_visible_label", "cldice", "centreline_recall")}
    bins = rows[0]["calibre_recall"].keys()
    out["calibre_recall"] = {b: float(np.mean([r["calibre_recall"][b] for r in rows if b in r["calibre_recall"]])) for b in bins}
    return out


@torch.no_grad()
def predict(net, image: np.ndarray) -> np.ndarray:
    net.eval()
    x = normalise(torch.from_numpy(np.ascontiguousarray(image, dtype=np.float32))[None, None])
    prob = torch.sigmoid(net(x))[0, 0].numpy()
    net.train()
    return prob > 0.5


def frangi_baseline(image: np.ndarray, voxel_mm: float) -> np.ndarray:
    from skimage.filters import frangi, threshold_otsu

    v = frangi(image.astype(np.float32), sigmas=[0.3 / voxel_mm, 0.6 / voxel_mm, 1.2 / voxel_mm], black_ridges=False)
    return v > threshold_otsu(v)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--minutes", type=float, default=6.0, help="training time")
    ap.add_argument("--out", default="out/train_unet")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--label-policy", choices=("visible", "binary"), default="visible", help="the training labels")
    a = ap.parse_args()
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    spec = SOURCE / "examples/dataset_train.toml"
    if a.label_policy != "visible":
        # The same spec with the policy set: a copy beside the results, its demand maps found from there.
        text = spec.read_text().replace('"../demand_maps/', '"' + str(SOURCE / "demand_maps") + "/")
        text = text.replace("[image]\n", f'[image]\nlabel_policy = "{a.label_policy}"\n', 1)
        spec = out / f"dataset_train_{a.label_policy}.toml"
        spec.write_text(text)
    torch.manual_seed(a.seed)
    torch.set_num_threads(max(1, (os.cpu_count() or 2) - 1))

    # Four patches of each sample, cut from one generation of it; the samples are independent
    # draws, so they need no shuffling.
    train = SyntheticVessels(spec, patch_size=(48, 48, 48), patches_per_sample=4, threads=1)
    loader = torch.utils.data.DataLoader(train, batch_size=2, shuffle=False, num_workers=1)
    test = list(angiosynth.Spec(SOURCE / "examples/dataset_small.toml"))
    voxel_mm = test[0].spacing[0]

    net = UNet3D()
    opt = torch.optim.Adam(net.parameters(), lr=2e-3)
    curve, evaluations = [], []
    t0 = time.monotonic()
    next_eval, step, samples_seen = 0.0, 0, 0
    for batch in loader:
        elapsed = time.monotonic() - t0
        if elapsed >= next_eval or elapsed > 60 * a.minutes:
            dice = [angiosynth.score(predict(net, s.image), s)["overlap"]["dice"] for s in test[:4]]
            evaluations.append({"seconds": elapsed, "step": step, "dice": float(np.mean(dice))})
            print(f"{elapsed:6.0f} s  step {step:5d}  held-out Dice (4 cases) {np.mean(dice):.3f}", flush=True)
            next_eval += 30.0
        if elapsed > 60 * a.minutes:
            break
        loss = loss_fn(net(normalise(batch["image"])), batch["label"].float())
        opt.zero_grad()
        loss.backward()
        opt.step()
        step += 1
        samples_seen += batch["image"].shape[0]
        curve.append({"seconds": time.monotonic() - t0, "step": step, "loss": float(loss)})
    train_seconds = time.monotonic() - t0

    rows = {"unet": [], "frangi": []}
    t1 = time.monotonic()
    for s in test:
        p = predict(net, s.image)
        rows["unet"].append(headline(angiosynth.score(p, s), p, s))
    unet_seconds = time.monotonic() - t1
    t1 = time.monotonic()
    for s in test:
        p = frangi_baseline(s.image, voxel_mm)
        rows["frangi"].append(headline(angiosynth.score(p, s), p, s))
    frangi_seconds = time.monotonic() - t1
    results = {
        "training": {"label_policy": a.label_policy, "seconds": train_seconds, "steps": step, "patches": samples_seen, "batch_size": 2, "patch": [48, 48, 48],
                     "parameters": sum(p.numel() for p in net.parameters())},
        "test_cases": len(test),
        "unet": {"mean": mean_scores(rows["unet"]), "seconds_for_test_set": unet_seconds},
        "frangi_otsu": {"mean": mean_scores(rows["frangi"]), "seconds_for_test_set": frangi_seconds},
        "evaluations": evaluations,
    }
    (out / "results.json").write_text(json.dumps(results, indent=2) + "\n")
    print(json.dumps({k: results[k]["mean"] for k in ("unet", "frangi_otsu")}, indent=2))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(10, 3.6))
    secs = np.array([c["seconds"] for c in curve])
    loss = np.array([c["loss"] for c in curve])
    k = max(1, len(loss) // 50)
    ax[0].plot(secs, loss, color="0.8", lw=0.8, label="per step")
    ax[0].plot(secs[k - 1 :], np.convolve(loss, np.ones(k) / k, mode="valid"), color="C0", label=f"mean of {k}")
    ax[0].set(xlabel="training time (s)", ylabel="BCE + soft Dice", title="training loss (on-the-fly samples)")
    ax[0].legend()
    ax[1].plot([e["seconds"] for e in evaluations], [e["dice"] for e in evaluations], "o-", label="3D U-Net")
    ax[1].axhline(results["frangi_otsu"]["mean"]["dice"], color="C3", ls="--", label="Frangi + Otsu")
    ax[1].set(xlabel="training time (s)", ylabel="Dice", title="held-out Dice", ylim=(0, 1))
    ax[1].legend()
    fig.tight_layout()
    fig.savefig(out / "training.png", dpi=110)


if __name__ == "__main__":
    main()
