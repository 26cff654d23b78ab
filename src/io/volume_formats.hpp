#pragma once
// The volume formats a sample's image and labels can be written in, one entry each: the
// parameter reader, the command line, `angiosynth params` and the writers all read this list.
// A new format is a writer in its own file and one entry in volume_formats.cpp.
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "io/volume_writers.hpp"

namespace angiosynth {

enum class VolumeFormatKind {
  PerChannel,   // each channel (image, mask, centreline, …) a file of its own, written by `write`
  Projections,  // the image's maximum-intensity projections as PNG pictures
  Sparse,       // every channel in one sparse OpenVDB file
  Chunked,      // every channel in one OME-Zarr store, rasterised chunk by chunk
};

struct VolumeFormat {
  std::string_view name;       // as written in [image] formats and --format
  std::string_view extension;  // PerChannel: of each channel's file
  std::string_view meaning;    // for help and the parameter reference
  VolumeFormatKind kind;
  void (*write)(const std::filesystem::path&, const VolumeView&) = nullptr;  // PerChannel only
};

std::span<const VolumeFormat> volumeFormats();
// The format of this name, or null.
const VolumeFormat* findVolumeFormat(std::string_view name);
std::vector<std::string> volumeFormatNames();
// "nifti (NIfTI-1, gzip), nrrd (…), …": the list with meanings, for help and references.
std::string volumeFormatSummary();

}  // namespace angiosynth
