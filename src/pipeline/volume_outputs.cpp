#include "pipeline/volume_outputs.hpp"

#include <cmath>
#include <cstdio>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/memory.hpp"
#include "io/graph_writers.hpp"
#include "io/text_file.hpp"
#include "io/vdb_writer.hpp"
#include "io/volume_writers.hpp"
#include "raster/ground_truth.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

template <class T>
Volume<T> convert(const Volume<float>& fraction, double background, double vessel) {
  Volume<T> out(fraction.grid);
  const double lo = std::is_integral_v<T> ? double(std::numeric_limits<T>::lowest()) : -INFINITY;
  const double hi = std::is_integral_v<T> ? double(std::numeric_limits<T>::max()) : INFINITY;
  for (std::size_t v = 0; v < out.data.size(); ++v) {
    const double x = background + (vessel - background) * fraction.data[v];
    out.data[v] = static_cast<T>(std::is_integral_v<T> ? std::clamp(std::round(x), lo, hi) : x);
  }
  return out;
}

void writeKeypoints(std::ostream& out, const VascularTree& t, const VolumeGrid& g) {
  out << "id,type,x_voxel,y_voxel,z_voxel,x_mm,y_mm,z_mm,radius_mm\n";
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    const Vec3& p = t.position[i];
    const Vec3 v = g.index(p);
    out << i << ',' << nodeTypeName(t.type(i)) << ',' << exactNumber(v.x) << ',' << exactNumber(v.y) << ',' << exactNumber(v.z)
        << ',' << exactNumber(p.x) << ',' << exactNumber(p.y) << ',' << exactNumber(p.z) << ',' << exactNumber(nodeRadius(t, i))
        << '\n';
  }
}

// Key points and the graph formats besides GXL and DOT.
void writeGraphFiles(const VascularTree& tree, const VolumeGrid& g, const ImageParameters& ip,
                     const std::filesystem::path& dir, Json& files) {
  writeTextFile(dir / "keypoints.csv", [&](std::ostream& o) { writeKeypoints(o, tree, g); });
  files["keypoints"] = "keypoints.csv";
  for (const auto& fmt : ip.graph_formats) {
    if (fmt == "csv") {
      writeTextFile(dir / "nodes.csv", [&](std::ostream& o) { writeNodesCsv(o, tree); });
      writeTextFile(dir / "edges.csv", [&](std::ostream& o) { writeEdgesCsv(o, tree); });
      files["nodes_csv"] = "nodes.csv";
      files["edges_csv"] = "edges.csv";
    } else if (fmt == "vtp") {
      writeTextFile(dir / "centerlines.vtp", [&](std::ostream& o) { writeVtp(o, tree); });
      files["vtp"] = "centerlines.vtp";
    } else if (fmt == "swc") {
      writeTextFile(dir / "tree.swc", [&](std::ostream& o) { writeSwc(o, tree); });
      files["swc"] = "tree.swc";
    } else if (fmt == "graphml") {
      writeTextFile(dir / "tree.graphml", [&](std::ostream& o) { writeGraphml(o, tree); });
      files["graphml"] = "tree.graphml";
    }
  }
}

}  // namespace

VolumeGrid imageGrid(const DemandMap& map, const ImageParameters& p) {
  VolumeGrid g;
  const double h = p.voxel_mm > 0 ? p.voxel_mm : map.voxel_mm;
  const Vec3 fov = p.field_of_view_mm.x > 0 ? p.field_of_view_mm : map.extentMm();
  for (int ax = 0; ax < 3; ++ax) {
    // Whole voxels covering the field of view (a hair of rounding does not add a voxel).
    g.dims[ax] = std::max(1, static_cast<int>(std::ceil(fov[ax] / h - 1e-9)));
  }
  g.spacing_mm = Vec3(h, h, h);
  g.origin_mm = Vec3(h / 2, h / 2, h / 2);
  return g;
}

VolumeGrid vascusynthGrid(const DemandMap& map, double output_voxel_mm) {
  VolumeGrid g;
  for (int ax = 0; ax < 3; ++ax)
    g.dims[ax] = static_cast<int>(std::floor(map.dims[ax] * map.voxel_mm / output_voxel_mm + 1e-9)) + 1;
  g.spacing_mm = Vec3(output_voxel_mm, output_voxel_mm, output_voxel_mm);
  g.origin_mm = Vec3(0, 0, 0);
  return g;
}

bool needsDense(const VolumeRequest& req) {
  return req.slices || std::any_of(req.image.formats.begin(), req.image.formats.end(), [](const std::string& f) { return f != "vdb"; });
}

void checkVolumeMemory(const VolumeRequest& req) {
  if (!needsDense(req)) return;  // the sparse path is checked once the tree is known
  const VolumeGrid& g = req.grid;
  const std::string size = std::to_string(g.dims[0]) + "x" + std::to_string(g.dims[1]) + "x" + std::to_string(g.dims[2]);
  // Every channel, the typed image, and slack for one more float volume during conversion.
  const std::uint64_t need = denseRasterBytes(g) + static_cast<std::uint64_t>(g.voxelCount()) * 4;
  if (need > req.memory_limit)
    throw InputError(req.parameter_file, req.image_line,
                     "an image of " + size + " voxels needs " + formatBytes(need) + " of memory, more than the limit of " +
                         formatBytes(req.memory_limit) +
                         "; raise [image] voxel_size, shrink [image] field_of_view, or raise --memory-limit");
}

void writeVolumes(const VascularTree& tree, const VolumeRequest& req, const std::filesystem::path& dir, Json& files,
                  Json& stats) {
  const VolumeGrid& g = req.grid;
  const ImageParameters& ip = req.image;
  checkVolumeMemory(req);
  if (std::find(ip.formats.begin(), ip.formats.end(), "vdb") != ip.formats.end()) {
    const BrickBins bins = binSegments(tree, g);
    const auto need = sparseRasterBytes(bins);
    if (need > req.memory_limit)
      throw InputError(req.parameter_file, req.image_line,
                       "the sparse volume needs about " + formatBytes(need) + ", more than the limit of " +
                           formatBytes(req.memory_limit) + "; raise [image] voxel_size or --memory-limit");
    const VdbReport r = writeVdb(dir / "volume.vdb", tree, g, bins, RasterOptions{ip.supersampling});
    files["vdb"] = "volume.vdb";
    stats["vdb_leaves"] = r.leaves;
    stats["vdb_active_voxels"] = r.active_voxels;
  }
  stats["image_size"] = {g.dims[0], g.dims[1], g.dims[2]};
  stats["image_voxel_size"] = Json{{"value", {g.spacing_mm.x, g.spacing_mm.y, g.spacing_mm.z}}, {"unit", "mm"}};
  stats["image_origin"] = Json{{"value", {g.origin_mm.x, g.origin_mm.y, g.origin_mm.z}},
                               {"unit", "mm"},
                               {"definition", "centre of voxel (0,0,0); world frame RAS+ (NIfTI, VDB), LPS in NRRD"}};
  writeGraphFiles(tree, g, ip, dir, files);
  if (!needsDense(req)) return;
  const GroundTruthVolumes gt = rasterizeGroundTruth(tree, g, RasterOptions{ip.supersampling});

  // Volumes in every requested format; the first format owns the plain role names.
  struct Channel {
    const char* role;
    VolumeView view;
  };
  Volume<std::uint8_t> img8;
  Volume<std::uint16_t> img16;
  Volume<std::int16_t> imgs16;
  Volume<float> imgf;
  VolumeView image_view;
  if (ip.dtype == "uint8") img8 = convert<std::uint8_t>(gt.fraction, ip.background, ip.vessel), image_view = viewOf(img8, false, "angiosynth image");
  else if (ip.dtype == "uint16") img16 = convert<std::uint16_t>(gt.fraction, ip.background, ip.vessel), image_view = viewOf(img16, false, "angiosynth image");
  else if (ip.dtype == "int16") imgs16 = convert<std::int16_t>(gt.fraction, ip.background, ip.vessel), image_view = viewOf(imgs16, false, "angiosynth image");
  else imgf = convert<float>(gt.fraction, ip.background, ip.vessel), image_view = viewOf(imgf, false, "angiosynth image");
  const Channel channels[] = {{"image", image_view},
                              {"mask", viewOf(gt.mask, true, "angiosynth vessel mask")},
                              {"centerline", viewOf(gt.centerline, true, "angiosynth centreline")},
                              {"radius", viewOf(gt.radius, false, "angiosynth radius (mm) on centreline")},
                              {"instances", viewOf(gt.instances, true, "angiosynth segment id")}};
  bool first_volume_format = true;
  for (const auto& fmt : ip.formats) {
    if (fmt == "vdb") continue;
    if (fmt == "png") {
      // Maximum-intensity projections of the partial-volume image along each axis.
      const char* axes[] = {"mip_x", "mip_y", "mip_z"};
      for (int ax = 0; ax < 3; ++ax) {
        const std::string name = std::string(axes[ax]) + ".png";
        writePng(dir / name, maximumProjection(gt.fraction, ax, 0.0, 1.0));
        files[axes[ax]] = name;
      }
      continue;
    }
    const std::string ext = fmt == "nifti" ? ".nii.gz" : (fmt == "nrrd" ? ".nrrd" : ".tif");
    for (const auto& c : channels) {
      const std::string name = std::string(c.role) + ext;
      if (fmt == "nifti") writeNifti(dir / name, c.view);
      else if (fmt == "nrrd") writeNrrd(dir / name, c.view);
      else writeTiff(dir / name, c.view);
      files[first_volume_format ? std::string(c.role) : std::string(c.role) + "_" + fmt] = name;
    }
    first_volume_format = false;
  }
  if (req.slices) {
    std::filesystem::create_directories(dir / req.slice_dir);
    writeNifti(dir / req.slice_dir / "image.nii.gz", image_view);
    files["original_image"] = req.slice_dir + "/image.nii.gz";
    for (std::int32_t z = 0; z < g.dims[2]; ++z) {
      char name[32];
      std::snprintf(name, sizeof name, "image%03d.png", z);
      writePng(dir / req.slice_dir / name, sliceZ(gt.fraction, z, 0.0, 1.0));
    }
    files["original_image_slices"] = req.slice_dir + "/image%03d.png";
  }
  std::int64_t mask_voxels = 0;
  for (auto m : gt.mask.data) mask_voxels += m;
  stats["mask_voxels"] = mask_voxels;
}

}  // namespace angiosynth
