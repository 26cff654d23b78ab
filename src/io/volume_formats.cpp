#include "io/volume_formats.hpp"

#include "io/format_lists.hpp"

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
    {"zarr", ".ome.zarr", "OME-Zarr: chunked, compressed, multiscale, every channel, made chunk by chunk in bounded memory",
     VolumeFormatKind::Chunked},
};

}  // namespace

std::span<const VolumeFormat> volumeFormats() { return kFormats; }

const VolumeFormat* findVolumeFormat(std::string_view name) { return findFormat(volumeFormats(), name); }
std::vector<std::string> volumeFormatNames() { return formatNames(volumeFormats()); }
std::string volumeFormatSummary() { return formatSummary(volumeFormats()); }

}  // namespace angiosynth
