#include "pipeline/volume_outputs.hpp"

#include <cmath>
#include <cstdio>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/memory.hpp"
#include "io/graph_writers.hpp"
#include "files/text_file.hpp"
#include "io/vdb_writer.hpp"
#include "io/volume_writers.hpp"
#include "pipeline/chunked_volume.hpp"
#include "pipeline/degraded_outputs.hpp"
#include "pipeline/label_outputs.hpp"
#include "pipeline/volume_files.hpp"
#include "settings/param_checks.hpp"
#include "raster/ground_truth.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

}  // namespace

std::int32_t axisVoxels(double n, const std::string& file, int line) {
  if (!(n <= 1e5))
    throw InputError(file, line,
                     "the image would be " + show(n) +
                         " voxels along one axis; allowed: at most 100000 "
                         "(raise [image] voxel_size or shrink field_of_view)");
  return std::max<std::int32_t>(1, static_cast<std::int32_t>(n));
}

VolumeGrid imageGrid(const DemandMap& map, const ImageParameters& p, const std::string& file, int line) {
  VolumeGrid g;
  const double h = p.voxel_mm.value_or(map.voxel_mm);
  const Vec3 fov = p.field_of_view_mm.value_or(map.extentMm());
  for (int ax = 0; ax < 3; ++ax) {
    // Whole voxels covering the field of view (a hair of rounding does not add a voxel).
    g.dims[ax] = axisVoxels(std::ceil(fov[ax] / h - 1e-9), file, line);
  }
  g.spacing_mm = Vec3(h, h, h);
  g.origin_mm = Vec3(h / 2, h / 2, h / 2);
  return g;
}

void SampleCapture::keep(const std::vector<Channel>& channels) {
  for (const Channel& c : channels) {
    const auto n = static_cast<std::size_t>(c.view.grid->voxelCount()) * voxelBytes(c.view.type);
    const auto* from = static_cast<const std::uint8_t*>(c.view.data);
    volumes.push_back(CapturedVolume{c.role, *c.view.grid, c.view.type, c.view.label, std::vector<std::uint8_t>(from, from + n)});
  }
}

bool needsDense(const VolumeRequest& req) {
  return req.vascusynth || !req.profiles.empty() || req.capture ||
         std::any_of(req.image.formats.begin(), req.image.formats.end(), [](const std::string& f) { return f != "vdb" && f != "zarr"; });
}

bool asks(const ImageParameters& ip, const char* format) { return std::find(ip.formats.begin(), ip.formats.end(), format) != ip.formats.end(); }

void checkVolumeMemory(const VolumeRequest& req) {
  if (!needsDense(req)) return;  // the sparse path is checked once the tree is known
  const VolumeGrid& g = req.grid;
  const std::string size = std::to_string(g.dims[0]) + "x" + std::to_string(g.dims[1]) + "x" + std::to_string(g.dims[2]);
  // Every channel, the typed image, and slack for one more float volume during conversion.
  std::uint64_t need = denseRasterBytes(g) + static_cast<std::uint64_t>(g.voxelCount()) * 4;
  // Profiles run one after another: the largest one counts.
  std::uint64_t profile_bytes = 0;
  for (const auto& p : req.profiles) profile_bytes = std::max(profile_bytes, degradedImageBytes(p, g));
  need += profile_bytes;
  if (!req.profiles.empty() || req.image.labels.writesLabel())
    need += labelBytesPerVoxel(req.image.labels) * static_cast<std::uint64_t>(g.voxelCount());
  if (need > req.memory_limit)
    throw InputError(req.parameter_file, req.image_line,
                     "an image of " + size + " voxels needs " + formatBytes(need) + " of memory, more than the limit of " +
                         formatBytes(req.memory_limit) + "; raise [image] voxel_size, shrink [image] field_of_view, or raise --memory-limit");
}

void writeVolumes(const Forest& forest, const VolumeRequest& req, const std::filesystem::path& dir, Json& files, Json& stats, Json& degradation,
                  Json* seconds) {
  const VascularTree& tree = forest.vessels;
  const VolumeGrid& g = req.grid;
  const ImageParameters& ip = req.image;
  checkVolumeMemory(req);
  if (req.write_files && std::find(ip.formats.begin(), ip.formats.end(), "vdb") != ip.formats.end()) {
    const double pairs = brickPairBound(tree, g);  // 12 bytes each while binning
    if (pairs * 12 > double(req.memory_limit))
      throw InputError(req.parameter_file, req.image_line,
                       "the sparse volume's bricks need about " + formatBytes(std::uint64_t(std::min(pairs * 12, 1e18))) +
                           " to sort, more than the limit of " + formatBytes(req.memory_limit) + "; raise [image] voxel_size or --memory-limit");
    const BrickBins bins = binSegments(tree, g);
    const auto need = sparseRasterBytes(bins);
    if (need > req.memory_limit)
      throw InputError(req.parameter_file, req.image_line,
                       "the sparse volume needs about " + formatBytes(need) + ", more than the limit of " + formatBytes(req.memory_limit) +
                           "; raise [image] voxel_size or --memory-limit");
    const VdbReport r = writeVdb(dir / "volume.vdb", tree, g, bins, RasterOptions{ip.supersampling, ip.centerline_connectivity});
    files["vdb"] = "volume.vdb";
    stats["vdb_leaves"] = r.leaves;
    stats["vdb_active_voxels"] = r.active_voxels;
  }
  if (req.write_files && asks(ip, "zarr")) {
    // One process, every chunk: the same store a cluster's tasks write (`angiosynth rasterize`).
    const ChunkedVolumeOptions o = chunkedVolumeOptions(ip, g, req.memory_limit);
    const auto store = dir / "volume.ome.zarr";
    openChunkedVolume(store, o, chunkedJob(o, "the tree of this sample"));
    const ChunkedVolumeSummary level0 = rasterizeChunks(forest, store, o, ChunkTask{});
    const PyramidSummary pyramid = buildPyramid(store, o, 1);
    files["zarr"] = "volume.ome.zarr";
    stats["zarr"] = Json{{"level0", level0.toJson()}, {"pyramid", pyramid.toJson()}};
    stats["zarr"]["level0"].erase("seconds");  // the sidecar's bytes depend on the sample alone
    stats["zarr"]["level0"].erase("memory_estimate_bytes");
    stats["zarr"]["pyramid"].erase("seconds");
  }
  stats["image_size"] = {g.dims[0], g.dims[1], g.dims[2]};
  stats["image_voxel_size"] = Json{{"value", {g.spacing_mm.x, g.spacing_mm.y, g.spacing_mm.z}}, {"unit", "mm"}};
  stats["image_origin"] = Json{{"value", {g.origin_mm.x, g.origin_mm.y, g.origin_mm.z}},
                               {"unit", "mm"},
                               {"definition", "centre of voxel (0,0,0); world frame RAS+ (NIfTI, VDB), LPS in NRRD"}};
  if (req.write_files) writeGraphFiles(tree, forest.trees, g, ip.graph_formats, "", dir, files);
  if (req.capture) {
    req.capture->grid = g;
    req.capture->has_grid = true;
  }
  if (!needsDense(req)) return;
  GroundTruthVolumes gt = rasterizeGroundTruth(tree, g, RasterOptions{ip.supersampling, ip.centerline_connectivity});
  const std::vector<std::uint8_t> classes = segmentClasses(tree, forest.trees);
  fillClasses(gt, tree, classes);
  {
    TypedImage image;
    makeTypedImage(image, gt.fraction, ip.background, ip.vessel - ip.background, ip.dtype, "angiosynth image");
    std::vector<Channel> channels{{"image", image.view}};
    for (auto& c : labelChannels(gt, "")) channels.push_back(c);
    // The binary label is the mask: its record needs no copy of it.
    Label label;
    if (ip.labels.writesLabel()) {
      label = makeLabel(ip.labels, gt, req.label_numbering);
      channels.push_back(labelChannel(label, ip.labels, "label"));
      stats["label"] = labelLengthKept(label, ip.labels, req.label_numbering, tree);
    } else {
      stats["label"] = labelLengthKept(&gt.mask, nullptr, ip.labels, req.label_numbering, tree);
    }
    if (req.capture) req.capture->keep(channels);
    if (req.write_files) {
      writeChannels(channels, ip.formats, dir, files);
      if (std::find(ip.formats.begin(), ip.formats.end(), "png") != ip.formats.end())
        writeMips(gt.fraction, previewClasses(forest.trees, gt), 0, 1, "", dir, files);
      if (req.vascusynth) writeVascuSynthSlices(image.view, gt.fraction, 0, 1, "original_image", *req.vascusynth, dir, files);
    }
  }
  std::int64_t mask_voxels = 0;
  for (auto m : gt.mask.data) mask_voxels += m;
  stats["mask_voxels"] = mask_voxels;
  writeDegradedImages(forest, classes, gt, req, dir, files, degradation, seconds);
}

}  // namespace angiosynth
