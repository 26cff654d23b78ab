#include "config/image_settings.hpp"

#include <cmath>

#include "io/graph_formats.hpp"
#include "io/volume_formats.hpp"
#include "settings/param_checks.hpp"

namespace angiosynth {

namespace {

std::string chunkProblem(double n) {
  return std::fmod(n, 8) == 0 ? "" : "zarr_chunk = " + show(n) + "; allowed: a multiple of 8 (the rasteriser's bricks) from 8 to 1024";
}

std::string connectivityProblem(double n) {
  return n == 6 || n == 26 ? "" : "centerline_connectivity = " + show(n) + "; allowed: 26 (a thin curve), 6 (face-connected)";
}

}  // namespace

// clang-format off
const std::vector<Setting<ImageParameters>>& imageSettings() {
  using P = ImageParameters;
  static const std::string volume_formats = "any of " + volumeFormatSummary();
  static const std::string graph_formats = "any of " + graphFormatSummary() + "; GXL and DOT are always written";
  static const SettingRange intensities{-Limits::kMaxIntensity, Limits::kMaxIntensity};
  static const std::vector<Setting<P>> settings{
      {.table = "image", .key = "enabled", .unit = "true/false", .fallback = "true", .meaning = "write volumes at all",
       .field = &P::enabled, .flag = "!--no-image"},
      {.table = "image", .key = "voxel_size", .unit = "mm", .fallback = "the domain's voxel",
       .meaning = "the image voxel edge (`voxel` = the domain's voxels)",
       .field = &P::voxel_mm, .range = {Limits::kMinVoxel, Limits::kMaxVoxel}, .quantity = Dimension::Length},
      {.table = "image", .key = "field_of_view", .unit = "[x, y, z] mm", .fallback = "the domain's extent",
       .meaning = "three lengths from the frame's corner",
       .field = &P::field_of_view_mm, .range = {0, Limits::kMaxLength, true, false}, .count = 3, .quantity = Dimension::Length},
      {.table = "image", .key = "supersampling", .unit = "count", .fallback = "4",
       .meaning = "S: S³ samples per partially covered voxel (1 … 16)", .field = &P::supersampling, .range = {1, 16}},
      {.table = "image", .key = "centerline_connectivity", .unit = "count", .fallback = "26",
       .meaning = "26: a thin voxel curve per segment; 6: every voxel a segment passes through (face-connected)",
       .field = &P::centerline_connectivity, .range = {6, 26}, .problem = connectivityProblem},
      {.table = "image", .key = "background", .unit = "", .fallback = "0", .meaning = "image intensity outside vessels",
       .field = &P::background, .range = intensities},
      {.table = "image", .key = "vessel", .unit = "", .fallback = "255",
       .meaning = "image intensity inside vessels (image = background + (vessel − background) × partial volume)",
       .field = &P::vessel, .range = intensities},
      {.table = "image", .key = "dtype", .unit = "text", .fallback = "uint8", .meaning = "uint8, uint16, int16 or float32",
       .field = &P::dtype, .choices = {"uint8", "uint16", "int16", "float32"}},
      {.table = "image", .key = "formats", .unit = "[text]", .fallback = "[\"nifti\", \"png\"]", .meaning = volume_formats.c_str(),
       .field = &P::formats, .choices = volumeFormatNames(), .flag = "--format"},
      {.table = "image", .key = "graph_formats", .unit = "[text]", .fallback = "[\"csv\", \"vtp\", \"swc\", \"graphml\"]",
       .meaning = graph_formats.c_str(), .field = &P::graph_formats, .choices = graphFormatNames()},
      {.table = "image", .key = "zarr_chunk", .unit = "count", .fallback = "128",
       .meaning = "formats = zarr: voxels along each edge of a chunk, a multiple of 8 (8 … 1024); memory per process follows the chunk, not the volume",
       .field = &P::zarr_chunk, .range = {8, 1024}, .problem = chunkProblem},
      {.table = "image", .key = "zarr_compression", .unit = "text", .fallback = "blosc",
       .meaning = "formats = zarr: blosc (LZ4, byte shuffle; zarr-python's default) or zlib",
       .field = &P::zarr_compression, .choices = {"blosc", "zlib"}},
      {.table = "image", .key = "zarr_levels", .unit = "count", .fallback = "0",
       .meaning = "formats = zarr: levels of the multiscale pyramid with the full resolution (each halves the voxels per axis); 0: until one chunk holds the volume",
       .field = &P::zarr_levels, .range = {0, 20}},
  };
  return settings;
}
// clang-format on

// clang-format off
const std::vector<Setting<LabelPolicy>>& labelSettings() {
  using P = LabelPolicy;
  static const std::vector<Setting<P>> settings{
      {.table = "image", .key = "label_policy", .unit = "text", .fallback = "binary",
       .meaning = "the training label (label.nii.gz; the mask stays as it is): binary (the mask), threshold, visible, soft or ignore "
                  "(a dataset with a degraded image: visible unless set)",
       .field = &P::name, .choices = labelPolicyNames()},
      {.table = "image", .key = "label_threshold", .unit = "", .fallback = "0.5",
       .meaning = "label_policy = threshold: vessel where the partial volume is at least this (0 … 1]",
       .field = &P::threshold, .range = {0, 1, true, false}, .only_with = {"label_policy", "threshold"}},
      {.table = "image", .key = "visible_snr", .unit = "", .fallback = "2",
       .meaning = "label_policy = visible: vessel where the noise-free contrast is at least this many noise sigmas of the image",
       .field = &P::visible_snr, .range = {0, 1000}, .only_with = {"label_policy", "visible"}},
      {.table = "image", .key = "ignore_band", .unit = "[low, high]", .fallback = "[0.25, 0.75]",
       .meaning = "label_policy = ignore: vessel at partial volume >= high; nnU-Net's ignore label on (low, high) and on centreline voxels below high",
       .field = &P::ignore_band, .range = {0, 1}, .count = 2, .only_with = {"label_policy", "ignore"}, .range_unit = "(partial volume)"},
  };
  return settings;
}
// clang-format on

// clang-format off
const std::vector<SettingRule<LabelPolicy>>& labelRules() {
  static const std::vector<SettingRule<LabelPolicy>> rules{
      {{"ignore_band"}, [](const LabelPolicy& p) -> std::string {
         if (p.ignoreLow() < p.ignoreHigh()) return "";
         return "ignore_band = [" + show(p.ignoreLow()) + ", " + show(p.ignoreHigh()) +
                "]; allowed: [low, high] partial volumes with 0 <= low < high <= 1";
       }},
  };
  return rules;
}
// clang-format on

}  // namespace angiosynth
