#pragma once
// [image]: how the tree becomes volumes, each setting declared once (imageSettings, and the
// training label's labelSettings). The parameter file's reader, `generate`'s flags, `angiosynth
// params` and the sidecar's parameters read these declarations.
#include <optional>
#include <string>
#include <vector>

#include "core/vec3.hpp"
#include "raster/label_policy.hpp"
#include "settings/schema.hpp"

namespace angiosynth {

// Defaults suit 8-bit images of the domain.
struct ImageParameters {
  bool enabled = true;
  std::optional<double> voxel_mm;                                          // unset: the domain's voxel
  std::optional<Vec3> field_of_view_mm;                                    // unset: the domain's extent
  int supersampling = 4;                                                   // S: S³ samples per partially covered voxel
  int centerline_connectivity = 26;                                        // of the centreline channel: 26 or 6
  double background = 0, vessel = 255;                                     // image = background + (vessel − background) × fraction
  std::string dtype = "uint8";                                             // uint8, uint16, int16, float32
  std::vector<std::string> formats{"nifti", "png"};                        // names of io/volume_formats.hpp
  std::vector<std::string> graph_formats{"csv", "vtp", "swc", "graphml"};  // names of io/graph_formats.hpp; GXL and DOT always
  int zarr_chunk = 128;                                                    // voxels along a chunk's edge (formats = zarr)
  std::string zarr_compression = "blosc";                                  // blosc (LZ4, shuffled) or zlib
  int zarr_levels = 0;                                                     // pyramid levels; 0: until one chunk holds the volume
  LabelPolicy labels;                                                      // the training label (label.nii.gz) beside the mask
};

// Every [image] setting but the label's, in the order of the reference.
const std::vector<Setting<ImageParameters>>& imageSettings();
// The [image] settings of the training label (ImageParameters::labels).
const std::vector<Setting<LabelPolicy>>& labelSettings();
const std::vector<SettingRule<LabelPolicy>>& labelRules();

}  // namespace angiosynth
