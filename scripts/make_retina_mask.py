#!/usr/bin/python3
"""Writes examples/retina/retina_slab.nii.gz, the domain of examples/colonisation_retina_3d.toml:
an 8 x 6 mm patch of inner retina 0.36 mm thick (0.03 mm voxels) centred on the fovea, less the
foveal avascular zone (a cylinder of radius 0.25 mm at x = +1.5 mm from the patch centre) and the
optic disc (radius 0.8 mm at x = -3.2 mm), where the vessels enter. Run from the repository root:
/usr/bin/python3 scripts/make_retina_mask.py"""
import nibabel as nib
import numpy as np

voxel = 0.03
nx, ny, nz = int(round(8 / voxel)), int(round(6 / voxel)), int(round(0.36 / voxel))
i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
x = (i + 0.5) * voxel - 4.0  # mm from the patch centre
y = (j + 0.5) * voxel - 3.0
inside = ~(((x - 1.5) ** 2 + y ** 2 < 0.25 ** 2) | ((x + 3.2) ** 2 + y ** 2 < 0.8 ** 2))
mask = np.repeat(inside[:, :, None], nz, axis=2).astype(np.uint8)
nib.save(nib.Nifti1Image(mask, np.diag([voxel, voxel, voxel, 1.0])), "examples/retina/retina_slab.nii.gz")
