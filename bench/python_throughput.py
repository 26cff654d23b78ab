#!/usr/bin/python3
"""Samples per second and peak memory: the Python module in memory against the program writing the
same dataset to disk, at 64^3 and 128^3 with the cta profile, for two specs of N = 500 trees:
bench/dataset_cco_500.toml (CCO in a sphere) and bench/dataset_200_128.toml (VascuSynth's method).

    /usr/bin/python3 bench/python_throughput.py [--samples 40] [--sizes 64 128] [--specs cco vascusynth]

Each way runs in a process of its own (peak RSS of that process and its children):
  cli            angiosynth dataset SPEC --out DIR (every core, samples in flight)
  cli+read       the same, then every image and label read back with nibabel (what a training loop reads)
  memory         spec[i] for each i in one process (every core per sample)
  memory-2       spec.iterate(): two samples at once on threads of one process (one core each)
  loader-0/-2    angiosynth.torch.SyntheticVessels in a DataLoader with 0 and 2 workers (whole volumes)
"""

import argparse
import json
import os
import pathlib
import resource
import subprocess
import sys
import tempfile
import time

SOURCE = pathlib.Path(__file__).resolve().parents[1]
BUILD = pathlib.Path(os.environ.get("ANGIOSYNTH_BUILD", SOURCE / "build"))


SPECS = {"cco": "bench/dataset_cco_500.toml", "vascusynth": "bench/dataset_200_128.toml"}


def spec_text(name: str, size: int, samples: int) -> str:
    text = (SOURCE / SPECS[name]).read_text()
    text = text.replace("../demand_maps/", str(SOURCE / "demand_maps") + "/")
    text = text.replace("samples = 200", f"samples = {samples}")
    assert 'voxel_size = "0.3125 mm"   # 40 mm / 128' in text
    return text.replace('voxel_size = "0.3125 mm"   # 40 mm / 128', f'voxel_size = "{40 / size} mm"')


def child(way: str, spec: str, samples: int, out: str) -> dict:
    sys.path.insert(0, str(BUILD / "python"))
    if way.startswith("loader"):
        import torch  # noqa: F401  (imported before the clock starts, as a training script has it)
    t0 = time.perf_counter()
    if way in ("cli", "cli+read"):
        subprocess.run([str(BUILD / "angiosynth"), "dataset", spec, "--out", out, "--quiet"], check=True)
        if way == "cli+read":
            import nibabel as nib
            import numpy as np

            root = next(pathlib.Path(out).glob("Dataset*"))
            for f in sorted((root / "imagesTr").glob("*.nii.gz")) + sorted((root / "labelsTr").glob("*.nii.gz")):
                np.asanyarray(nib.load(str(f)).dataobj)
    elif way == "memory":
        import angiosynth

        s = angiosynth.Spec(spec)
        for i in range(samples):
            s[i].image
    elif way == "memory-2":
        import angiosynth

        for sample in angiosynth.Spec(spec).iterate(in_flight=2):
            sample.image
    else:
        import torch

        from angiosynth.torch import SyntheticVessels

        workers = int(way.split("-")[1])
        loader = torch.utils.data.DataLoader(SyntheticVessels(spec), batch_size=None, num_workers=workers)
        for item in loader:
            item["image"]
    seconds = time.perf_counter() - t0
    rss = max(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
    return {"way": way, "seconds": seconds, "samples_per_second": samples / seconds, "peak_rss_mib": rss / 1024}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--samples", type=int, default=40)
    ap.add_argument("--sizes", type=int, nargs="+", default=[64, 128])
    ap.add_argument("--specs", nargs="+", default=["cco", "vascusynth"], choices=sorted(SPECS))
    ap.add_argument("--ways", nargs="+", default=["cli", "cli+read", "memory", "memory-2", "loader-0", "loader-2"])
    ap.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        print(json.dumps(child(a.child[0], a.child[1], int(a.child[2]), a.child[3])))
        return
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, size in [(n, s) for n in a.specs for s in a.sizes]:
            spec = pathlib.Path(tmp) / f"bench_{name}_{size}.toml"
            spec.write_text(spec_text(name, size, a.samples))
            for way in a.ways:
                out = pathlib.Path(tmp) / f"out_{name}_{size}_{way}"
                out.mkdir()
                done = subprocess.run([sys.executable, __file__, "--child", way, str(spec), str(a.samples), str(out)], capture_output=True, text=True)
                if done.returncode:
                    sys.exit(done.stderr)
                r = json.loads(done.stdout.strip().splitlines()[-1])
                r["size"], r["spec"] = size, name
                rows.append(r)
                print(f"{name:10s} {size}^3  {way:9s} {r['samples_per_second']:6.2f} samples/s  {r['seconds']:7.1f} s  peak RSS {r['peak_rss_mib']:6.0f} MiB", flush=True)
    print("\n| spec | size | way | samples/s | × cli | peak RSS (MiB) |\n|---|---|---|---|---|---|")
    for r in rows:
        cli = next(c for c in rows if c["size"] == r["size"] and c["spec"] == r["spec"] and c["way"] == "cli")
        print(f"| {r['spec']} | {r['size']}³ | {r['way']} | {r['samples_per_second']:.2f} | {r['samples_per_second'] / cli['samples_per_second']:.1f} | {r['peak_rss_mib']:.0f} |")


if __name__ == "__main__":
    main()
