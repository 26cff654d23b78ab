#!/usr/bin/env bash
# GNU parallel: 20 shards over the hosts in ~/.parallel/sshloginfile (or locally with -j N),
# then one merge. The same shards as the Slurm and Kubernetes examples make the same dataset.
set -euo pipefail
OUT=${OUT:-$PWD/out/nnUNet_raw}
seq 0 19 | parallel --halt now,fail=1 -j 4 \
  angiosynth dataset examples/dataset_large.toml --out "$OUT" --shard {}/20 --resume --threads 1 --quiet
angiosynth dataset finalize "$OUT"/Dataset911_VesselCTA
angiosynth dataset verify "$OUT"/Dataset911_VesselCTA
