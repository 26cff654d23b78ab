"""The PyTorch dataset: the same items whatever the DataLoader's workers, channel-first tensors."""

import numpy as np
import pytest

torch = pytest.importorskip("torch")

import angiosynth  # noqa: E402
from angiosynth.torch import SyntheticVessels  # noqa: E402


def items(data, workers):
    loader = torch.utils.data.DataLoader(data, batch_size=None, num_workers=workers, shuffle=False)
    return [(b["index"], b["image"], b["label"], b["patch_origin"]) for b in loader]


def test_items_are_the_same_with_zero_and_two_workers(source):
    data = SyntheticVessels(source / "tests/data/dataset_tiny.toml", patch_size=(16, 16, 16), patches_per_sample=2, indices=[0, 3, 5])
    assert len(data) == 6
    serial, parallel = items(data, 0), items(data, 2)
    for (i0, im0, lb0, at0), (i2, im2, lb2, at2) in zip(serial, parallel):
        assert i0 == i2 and torch.equal(im0, im2) and torch.equal(lb0, lb2) and torch.equal(at0, at2)
    # Two patches of one sample are drawn apart; the item is the spec's sample, cut at its origin.
    assert not torch.equal(serial[0][3], serial[1][3])
    s = angiosynth.Spec(source / "tests/data/dataset_tiny.toml")[3]
    x, y, z = serial[2][3].tolist()
    assert np.array_equal(serial[2][1][0].numpy(), s.image[x : x + 16, y : y + 16, z : z + 16].astype(np.float32))


def test_whole_volumes_are_channel_first_with_labels_as_stored(source):
    data = SyntheticVessels(source / "tests/data/dataset_tiny.toml", extra=["centerline"])
    item = data[1]
    assert item["image"].dtype == torch.float32 and item["image"].shape == (1, 32, 32, 32)
    assert item["label"].dtype == torch.uint8 and set(item["label"].unique().tolist()) <= {0, 1}
    assert item["centerline"].shape == (1, 32, 32, 32)
    data.set_epoch(1)
    assert torch.equal(data[1]["image"], item["image"])  # whole volumes: the epoch draws nothing
