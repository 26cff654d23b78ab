#pragma once
// Reading one 3D NIfTI-1 volume with its geometry (voxel size in mm, the voxel-to-world affine),
// every header value checked before the voxels are read.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>

#include "raster/volume.hpp"

namespace angiosynth {

struct NiftiVolume {
  Volume<float> values;             // scaled by scl_slope/scl_inter when the header sets them
  std::array<double, 12> affine{};  // rows of the voxel-to-world (mm) matrix: sform, else qform
  // The qform as well, when the header sets both: writers round the two differently, and a
  // prediction written by another tool may keep either.
  std::optional<std::array<double, 12>> other_affine;
};

// `bytes_per_voxel`: what the caller will hold per voxel, for the memory check against `limit`.
NiftiVolume readNiftiVolume(const std::filesystem::path& file, std::uint64_t limit, std::uint64_t bytes_per_voxel, const char* what);

}  // namespace angiosynth
