#pragma once
// VascuSynth's output layout (Hamarneh & Jassi 2010), which `angiosynth vascusynth` writes for
// scripts made for VascuSynth: NAME/tree_structure.xml in VascuSynth's GXL dialect and tree.dot;
// original_image/ with image.nii.gz and one 8-bit slice per z; one <noise>/ of the same per noise
// file (noise_image_<i>). The rest of the pipeline asks only whether a sample has this layout.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "core/forest.hpp"
#include "domain/demand_map.hpp"
#include "io/graph_writers.hpp"
#include "io/volume_writers.hpp"
#include "raster/volume.hpp"

namespace angiosynth {

struct VascuSynthLayout {
  double voxel_mm = 0;               // OUTPUT_VOXEL_WIDTH: the image grid's step
  std::string slice_format = "jpg";  // jpg (what VascuSynth writes; lossy) or png (lossless)
};

// VascuSynth's output grid: floor(map size × VOXEL_WIDTH / OUTPUT_VOXEL_WIDTH) + 1 samples per
// axis at i·OUTPUT_VOXEL_WIDTH (map-voxel corners), so a 100³ map at 0.04/0.04 gives 101³.
VolumeGrid vascusynthGrid(const DemandMap& map, double output_voxel_mm, const std::string& file = "", int line = 0);
inline constexpr const char* kVascuSynthGridRule =
    "VascuSynth's: floor(map size x VOXEL_WIDTH / OUTPUT_VOXEL_WIDTH) + 1 voxels per axis, centred on the map voxels' corners "
    "(i x OUTPUT_VOXEL_WIDTH from the map's corner); a 100^3 map at 0.04/0.04 gives 101^3";

// tree_structure.xml (VascuSynth's GXL, the graph named `graph_id`) and tree.dot.
void writeVascuSynthGraphs(const Forest& forest, const GraphFrame& frame, const std::string& graph_id, const std::filesystem::path& dir,
                           nlohmann::ordered_json& files);

// <sub>/image.nii.gz (the exact image) and one 8-bit slice per z, image000.<format>, [lo, hi] →
// [0, 255]: original_image/ for the clean image, the noise's name for each noise file.
void writeVascuSynthSlices(const VolumeView& image, const Volume<float>& shown, double lo, double hi, const std::string& sub,
                           const VascuSynthLayout& layout, const std::filesystem::path& dir, nlohmann::ordered_json& files);

}  // namespace angiosynth
