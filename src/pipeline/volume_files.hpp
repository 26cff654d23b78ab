#pragma once
// Writing a set of volumes (one sample's channels, clean or degraded) in every requested format,
// recorded by role: the first volume format owns the plain role, later ones add _<format>.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/forest.hpp"
#include "io/volume_writers.hpp"
#include "raster/ground_truth.hpp"

namespace angiosynth {

// A float volume converted to the sample's dtype (rounded and clamped for integer types);
// owns its voxels, `view` points at them.
struct TypedImage {
  Volume<std::uint8_t> u8;
  Volume<std::uint16_t> u16;
  Volume<std::int16_t> s16;
  Volume<float> f32;
  VolumeView view;
};
// offset + scale × src, as dtype (uint8, uint16, int16, float32).
void makeTypedImage(TypedImage& out, const Volume<float>& src, double offset, double scale, const std::string& dtype, const std::string& description);

struct Channel {
  std::string role;  // also the file stem
  VolumeView view;
};

// The label channels of a ground truth (mask, centerline, radius, instances, classes when filled), with `suffix`
// appended to each role ("" or "_<profile>").
std::vector<Channel> labelChannels(const GroundTruthVolumes& gt, const std::string& suffix);

// Writes the channels in each per-channel volume format (projections and sparse grids are written elsewhere).
void writeChannels(const std::vector<Channel>& channels, const std::vector<std::string>& formats, const std::filesystem::path& dir,
                   nlohmann::ordered_json& files);
// Maximum-intensity projections along x, y, z as mip_<axis><suffix>.png, [lo, hi] → [0, 255]; in
// colour by the kind of the brightest voxel (artery red, vein blue, ...) when `classes` is given.
void writeMips(const Volume<float>& v, const Volume<std::uint8_t>* classes, double lo, double hi, const std::string& suffix,
               const std::filesystem::path& dir, nlohmann::ordered_json& files);
// The classes volume to colour previews with: unless every tree is an artery (grey, as before forests).
inline const Volume<std::uint8_t>* previewClasses(const std::vector<TreeInfo>& trees, const GroundTruthVolumes& gt) {
  const bool kinds = std::any_of(trees.begin(), trees.end(), [](const TreeInfo& t) { return t.class_label != 1; });
  return kinds && !gt.classes.data.empty() ? &gt.classes : nullptr;
}
// Key points and the graph formats besides GXL and DOT (csv, vtp, swc, graphml), with `suffix`
// appended to file stems and roles.
void writeGraphFiles(const VascularTree& tree, const std::vector<TreeInfo>& trees, const VolumeGrid& g, const std::vector<std::string>& graph_formats,
                     const std::string& suffix, const std::filesystem::path& dir, nlohmann::ordered_json& files);

}  // namespace angiosynth
