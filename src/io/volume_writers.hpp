#pragma once
// Volume writers. Conventions shared by every format:
// - angiosynth's mm frame is taken as the RAS+ world frame of NIfTI (+x right, +y anterior,
//   +z superior); voxel (i,j,k) is centred at origin + (i·sx, j·sy, k·sz) with x fastest.
// - NRRD is written in LPS (its usual space), so x and y axes and origin are negated there:
//   the same physical geometry in every viewer.
// Every writer throws InputError(path, 0, …) when the file cannot be written.
#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "raster/volume.hpp"

namespace angiosynth {

enum class VoxelType { UInt8, Int16, UInt16, UInt32, Float32 };

// A typed, read-only view of a volume's voxels.
struct VolumeView {
  const VolumeGrid* grid = nullptr;
  const void* data = nullptr;
  VoxelType type = VoxelType::Float32;
  bool label = false;       // label map: NIfTI intent LABEL, nearest-neighbour semantics
  std::string description;  // ≤ 79 characters, stored in the header
};

template <class T>
constexpr VoxelType voxelTypeOf();
template <>
constexpr VoxelType voxelTypeOf<std::uint8_t>() {
  return VoxelType::UInt8;
}
template <>
constexpr VoxelType voxelTypeOf<std::int16_t>() {
  return VoxelType::Int16;
}
template <>
constexpr VoxelType voxelTypeOf<std::uint16_t>() {
  return VoxelType::UInt16;
}
template <>
constexpr VoxelType voxelTypeOf<std::uint32_t>() {
  return VoxelType::UInt32;
}
template <>
constexpr VoxelType voxelTypeOf<float>() {
  return VoxelType::Float32;
}

template <class T>
VolumeView viewOf(const Volume<T>& v, bool label, std::string description) {
  return {&v.grid, v.data.data(), voxelTypeOf<T>(), label, std::move(description)};
}

std::size_t voxelBytes(VoxelType t);

// NIfTI-1, gzip-compressed (.nii.gz): sform = qform, code 1 (scanner), mm units.
void writeNifti(const std::filesystem::path& file, const VolumeView& v);
// The same whole or not at all (files/atomic_file), with the voxel-to-world `affine` (rows; from
// another file, e.g. the image a mask was made from) instead of the grid's when given.
void writeNiftiAtomically(const std::filesystem::path& file, const VolumeView& v, const std::array<double, 12>* affine, bool replace);
// NRRD with gzip encoding, space left-posterior-superior.
void writeNrrd(const std::filesystem::path& file, const VolumeView& v);
// MetaImage (.mha), zlib-compressed, in ITK's LPS space.
void writeMetaImage(const std::filesystem::path& file, const VolumeView& v);

}  // namespace angiosynth

namespace angiosynth {

// Multi-page TIFF (one page per z slice, deflate-compressed, lossless) through libtiff.
void writeTiff(const std::filesystem::path& file, const VolumeView& v);

// A 2D 8-bit image (row-major, width fastest): grey, or RGB with `channels` = 3 interleaved.
struct Image8 {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;
  int channels = 1;
};
// Maximum-intensity projection along axis 0, 1 or 2, mapping [lo, hi] to [0, 255]. The image
// shows the two remaining axes in increasing order (the lower one horizontal), index 0 at the
// top left.
Image8 maximumProjection(const Volume<float>& v, int axis, double lo, double hi);
// The same projection in colour: each pixel takes the colour (0xRRGGBB, from `colour_of(label)`)
// of the label of the voxel that gave its maximum (the first along the axis on ties), scaled by
// its intensity; label 0 stays grey.
Image8 maximumProjection(const Volume<float>& v, const Volume<std::uint8_t>& labels, std::uint32_t (*colour_of)(int), int axis, double lo, double hi);
// Slice z of a volume, mapping [lo, hi] to [0, 255].
Image8 sliceZ(const Volume<float>& v, std::int32_t z, double lo, double hi);
// Lossless 8-bit PNG through libpng.
void writePng(const std::filesystem::path& file, const Image8& image);
// The same into an open stream (an AtomicFile's); `file` names it in errors.
void writePng(std::FILE* out, const std::filesystem::path& file, const Image8& image);
// The PNG's bytes (for a data URI, or a file written whole or not at all).
std::string encodePng(const Image8& image);
// Baseline JPEG through libjpeg (lossy: VascuSynth's slice format, kept for its users' scripts).
void writeJpeg(const std::filesystem::path& file, const Image8& image, int quality = 95);

}  // namespace angiosynth
