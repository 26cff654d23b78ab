#pragma once
// The volume stage of a sample: grid, size guard, rasterisation, and every volume, key-point and
// graph file, recorded by role for sample.json.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "degrade/profile.hpp"
#include "domain/demand_map.hpp"
#include "core/forest.hpp"
#include "io/graph_writers.hpp"
#include "config/scenario.hpp"
#include "pipeline/vascusynth_layout.hpp"
#include "pipeline/volume_files.hpp"
#include "raster/label_policy.hpp"
#include "raster/volume.hpp"

namespace angiosynth {

// The image grid over the demand map: voxel size and field of view from the parameters, by
// default the map's own; voxel centres at (i + ½)·voxel from the map's corner.
inline constexpr const char* kImageGridRule =
    "field_of_view / voxel_size voxels per axis (rounded up), centred at (i + 1/2) x voxel_size from the frame's corner: the map voxels' "
    "centres when voxel_size is the map's (`angiosynth vascusynth` writes VascuSynth's grid of corners instead)";
VolumeGrid imageGrid(const DemandMap& map, const ImageParameters& p, const std::string& file = "", int line = 0);
// Voxels along one axis of an image, refused past 10^5 before any integer conversion.
std::int32_t axisVoxels(double n, const std::string& file, int line);

// A sample's products kept in memory as the pipeline makes them (the Python module's samples):
// each volume by its role (the file stem the CLI writes it under), the final forest, and the tree
// and warp of every profile that moves the geometry.
struct CapturedVolume {
  std::string role;
  VolumeGrid grid;
  VoxelType type = VoxelType::Float32;
  bool label = false;
  std::vector<std::uint8_t> bytes;  // x fastest, as in the files
};
struct WarpedTree {
  std::string profile;
  VascularTree tree;
  nlohmann::ordered_json warp;  // the warp's description (warp_<profile>.json)
};
struct SampleCapture {
  std::vector<CapturedVolume> volumes;
  Forest forest;
  VolumeGrid grid;  // of the clean volumes (unset when no volume was made)
  bool has_grid = false;
  GraphFrame frame;
  std::vector<WarpedTree> warped;
  void keep(const std::vector<Channel>& channels);
};

struct VolumeRequest {
  VolumeGrid grid;
  ImageParameters image;
  std::uint64_t memory_limit = 0;
  std::string parameter_file;  // for size errors
  int image_line = 0;
  std::optional<VascuSynthLayout> vascusynth;  // VascuSynth's layout: slices of each image
  // Degradation: one image per profile (role image_<profile>), drawn from (seed, sample).
  std::vector<Profile> profiles;
  std::uint64_t seed = 1, sample = 0;
  GraphFrame frame;                  // for the GXL of warped trees
  LabelNumbering label_numbering;    // vessel 1 (or each kind's class), ignore value
  SampleCapture* capture = nullptr;  // also keep every volume in memory
  bool write_files = true;           // false: nothing goes to disk (capture holds the products)
};

// Throws InputError when the request's volumes would exceed its memory limit.
void checkVolumeMemory(const VolumeRequest& req);

// Writes the volumes and graph files into dir; adds {role: path} to `files` and figures to
// `stats`, and the drawn values of each profile to `degradation`. Throws InputError before allocating when the volumes would exceed the memory limit.
void writeVolumes(const Forest& forest, const VolumeRequest& req, const std::filesystem::path& dir, nlohmann::ordered_json& files,
                  nlohmann::ordered_json& stats, nlohmann::ordered_json& degradation, nlohmann::ordered_json* seconds = nullptr);

}  // namespace angiosynth
