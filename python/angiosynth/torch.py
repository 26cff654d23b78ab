"""A PyTorch dataset that generates a Spec's samples on the fly, in memory.

    from angiosynth.torch import SyntheticVessels
    data = SyntheticVessels("examples/dataset_small.toml", patch_size=(48, 48, 48))
    loader = torch.utils.data.DataLoader(data, batch_size=2, num_workers=2)
    for batch in loader:
        batch["image"]   # float32, (B, 1, X, Y, Z): channel first, as nnU-Net and MONAI expect
        batch["label"]   # uint8 (B, 1, X, Y, Z): labelsTr's values (float32 for the soft label policy);
                         # .long() for a cross-entropy loss, .float() for Dice or BCE

Seeding rule: item k is sample k // patches_per_sample of the spec, which depends on the spec and
that index alone (its seed is drawn from [dataset] seed and the index). The patch of item k is
drawn from numpy's SeedSequence((spec seed, sample index, patch number, epoch)). So an item is the
same whatever the DataLoader's number of workers, their order or the process; `set_epoch(e)`
draws new patches of the same samples. Torch is needed for this module only.
"""

from __future__ import annotations

import os
from typing import Callable, Sequence

import numpy as np
import torch
import torch.utils.data

from . import Spec

__all__ = ["SyntheticVessels"]


class SyntheticVessels(torch.utils.data.Dataset):
    """Spec samples as training pairs, made when asked.

    spec                a dataset spec (path or angiosynth.Spec)
    patch_size          (x, y, z) voxels of a random patch per item, or None for the whole volume
    patches_per_sample  items per sample (each its own patch); consecutive items of one sample are
                        cut from one generation of it, so keep them together (shuffle=False: the
                        samples are independent draws already, or a sampler that keeps runs)
    indices             the spec's samples to use (default: all); e.g. a train/validation split
    extra               more volumes of the sample to return, by role: "centerline", "radius", "classes", ...
    threads             TBB threads per call (default: every core in the main process, 1 in a DataLoader worker)
    transform           called on the item dict before it is returned
    """

    def __init__(
        self,
        spec: str | os.PathLike | Spec,
        patch_size: Sequence[int] | None = None,
        patches_per_sample: int = 1,
        indices: Sequence[int] | None = None,
        extra: Sequence[str] = (),
        threads: int | None = None,
        transform: Callable[[dict], dict] | None = None,
    ):
        self.spec = spec if isinstance(spec, Spec) else Spec(spec)
        self.patch_size = tuple(int(p) for p in patch_size) if patch_size is not None else None
        if self.patch_size is not None and (len(self.patch_size) != 3 or min(self.patch_size) < 1):
            raise ValueError(f"patch_size is {patch_size}; allowed: three positive voxel counts (x, y, z)")
        if patches_per_sample < 1:
            raise ValueError(f"patches_per_sample is {patches_per_sample}; allowed: 1 or more")
        self.patches_per_sample = patches_per_sample
        self.indices = list(range(len(self.spec))) if indices is None else [int(i) for i in indices]
        self.extra = tuple(extra)
        self.threads = threads
        self.transform = transform
        self.epoch = 0
        self._last = None  # (index, sample): the patches of one sample share it when they come in a row

    def set_epoch(self, epoch: int) -> None:
        """New patches (of the same samples) for another epoch."""
        self.epoch = int(epoch)

    def __len__(self) -> int:
        return len(self.indices) * self.patches_per_sample

    def _threads(self) -> int:
        if self.threads is not None:
            return self.threads
        return 1 if torch.utils.data.get_worker_info() is not None else 0

    def _patch(self, shape: Sequence[int], index: int, k: int) -> tuple[slice, slice, slice]:
        if self.patch_size is None:
            return (slice(None),) * 3
        rng = np.random.default_rng(np.random.SeedSequence([self.spec.seed, index, k, self.epoch]))
        starts = [int(rng.integers(0, max(1, n - p + 1))) for n, p in zip(shape, self.patch_size)]
        return tuple(slice(s, s + p) for s, p in zip(starts, self.patch_size))

    @staticmethod
    def _padded(a: np.ndarray, size: Sequence[int] | None) -> np.ndarray:
        if size is None or all(n >= p for n, p in zip(a.shape, size)):
            return a
        return np.pad(a, [(0, max(0, p - n)) for n, p in zip(a.shape, size)])

    def __getitem__(self, item: int) -> dict:
        if not 0 <= item < len(self):
            raise IndexError(f"item {item} of {len(self)}")
        index = self.indices[item // self.patches_per_sample]
        k = item % self.patches_per_sample
        if self._last is None or self._last[0] != index:
            self.spec.threads = self._threads()
            self._last = (index, self.spec[index])
        s = self._last[1]
        where = self._patch(s.image.shape, index, k)
        # Arrays keep the module's layout (x fastest): the tensors are strided views, which
        # collation and convolution accept; no copy is made but the image's float conversion.
        image = self._padded(np.asarray(s.image[where], dtype=np.float32), self.patch_size)
        label = self._padded(s.label[where], self.patch_size)
        out = {
            "image": torch.from_numpy(image[None]),
            "label": torch.from_numpy(label[None]),
            "index": index,
            "id": s.id,
            "patch_origin": torch.tensor([w.start or 0 for w in where]),
            "affine": torch.from_numpy(s.affine),
        }
        for role in self.extra:
            out[role] = torch.from_numpy(self._padded(s.volumes[role][where], self.patch_size)[None])
        return self.transform(out) if self.transform else out
