#include "io/volume_formats.hpp"

namespace angiosynth {
namespace {

// The order is the order a sample records them: the first per-channel format owns the plain
// role names in sample.json (`mask`), later ones add _<format> (`mask_nrrd`).
constexpr VolumeFormat kFormats[] = {
    {"nifti", ".nii.gz", "NIfTI-1, gzip", VolumeFormatKind::PerChannel, &writeNifti},
    {"nrrd", ".nrrd", "NRRD, gzip, LPS", VolumeFormatKind::PerChannel, &writeNrrd},
    {"tiff", ".tif", "multi-page TIFF, deflate", VolumeFormatKind::PerChannel, &writeTiff},
    {"mha", ".mha", "MetaImage, zlib, LPS (ITK, 3D Slicer)", VolumeFormatKind::PerChannel, &writeMetaImage},
    {"png", "", "maximum-intensity projections", VolumeFormatKind::Projections},
    {"vdb", ".vdb", "sparse OpenVDB grids", VolumeFormatKind::Sparse},
};

}  // namespace

std::span<const VolumeFormat> volumeFormats() { return kFormats; }

const VolumeFormat* findVolumeFormat(std::string_view name) {
  for (const auto& f : kFormats)
    if (f.name == name) return &f;
  return nullptr;
}

std::vector<std::string> volumeFormatNames() {
  std::vector<std::string> names;
  for (const auto& f : kFormats) names.emplace_back(f.name);
  return names;
}

std::string volumeFormatSummary() {
  std::string s;
  for (const auto& f : kFormats) {
    if (!s.empty()) s += ", ";
    s += std::string(f.name) + " (" + std::string(f.meaning) + ")";
  }
  return s;
}

}  // namespace angiosynth
