#!/usr/bin/python3
"""A stand-in segmenter for trying `angiosynth score --dataset`: each image of a dataset's
imagesTr thresholded three noise sigmas above its background (vessels fill a few percent of the
voxels, so the median is the background's level and 1.4826 times the median absolute deviation
its noise sigma), written as PRED_DIR/<case>.nii.gz, the names nnU-Net's predictions have.
Replace it with your model's predictions.

    /usr/bin/python3 examples/threshold_dataset.py DATASET_DIR PRED_DIR
"""
import pathlib
import sys

import nibabel as nib
import numpy as np


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    dataset, predictions = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    images = sorted((dataset / "imagesTr").glob("*_0000.nii.gz"))
    if not images:
        print(f"{dataset}/imagesTr holds no <case>_0000.nii.gz images", file=sys.stderr)
        return 2
    predictions.mkdir(parents=True, exist_ok=True)
    for image in images:
        volume = nib.load(image)
        data = np.asanyarray(volume.dataobj).astype(np.float32)
        background = np.median(data)
        sigma = 1.4826 * np.median(np.abs(data - background))
        mask = (data > background + 3 * sigma).astype(np.uint8)
        case = image.name[: -len("_0000.nii.gz")]
        nib.save(nib.Nifti1Image(mask, volume.affine), predictions / f"{case}.nii.gz")
    print(f"wrote {len(images)} predictions to {predictions}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
