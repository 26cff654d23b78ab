#include "pipeline/volume_files.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "core/format.hpp"
#include "degrade/effect.hpp"
#include "io/graph_formats.hpp"
#include "io/graph_writers.hpp"
#include "io/network_files.hpp"
#include "io/volume_formats.hpp"
#include "files/text_file.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

template <class T>
void convert(Volume<T>& out, const Volume<float>& src, double offset, double scale) {
  // Every voxel is written below: storage of the same size is reused as it is.
  if (out.data.size() != src.data.size()) out.data = VoxelBuffer<T>(src.data.size());
  out.grid = src.grid;
  constexpr bool integral = std::is_integral_v<T>;
  // Saturating: a value beyond the type (or NaN, as 0) never reaches an undefined conversion.
  const double lo = double(std::numeric_limits<T>::lowest()), hi = double(std::numeric_limits<T>::max());
  const auto typed = [&](double x) { return std::isnan(x) ? T(0) : static_cast<T>(std::clamp(integral ? std::round(x) : x, lo, hi)); };
  // Most voxels of a vessel image are background: their value once (the same arithmetic).
  const T background = typed(offset + scale * 0.0f);
  forEachVoxel(static_cast<std::int64_t>(src.data.size()), [&](std::int64_t v) {
    out.data[v] = src.data[v] == 0 && !std::signbit(src.data[v]) ? background : typed(offset + scale * src.data[v]);
  });
}

void writeKeypoints(std::ostream& out, const VascularTree& t, const std::vector<TreeInfo>& trees, const VolumeGrid& g) {
  out << "id,type,x_voxel,y_voxel,z_voxel,x_mm,y_mm,z_mm,radius_mm,tree,kind\n";
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    if (t.isLink(i)) continue;  // an N-ary junction is one key point
    const Vec3& p = t.position[i];
    const Vec3 v = g.index(p);
    out << i << ',' << nodeTypeName(t.graphType(i)) << ',' << exactNumber(v.x) << ',' << exactNumber(v.y) << ',' << exactNumber(v.z) << ','
        << exactNumber(p.x) << ',' << exactNumber(p.y) << ',' << exactNumber(p.z) << ',' << exactNumber(nodeRadius(t, i)) << ','
        << treeOf(trees, t, i).id << ',' << treeOf(trees, t, i).kind << '\n';
  }
}

}  // namespace

void makeTypedImage(TypedImage& out, const Volume<float>& src, double offset, double scale, const std::string& dtype,
                    const std::string& description) {
  if (dtype == "uint8")
    convert(out.u8, src, offset, scale), out.view = viewOf(out.u8, false, description);
  else if (dtype == "uint16")
    convert(out.u16, src, offset, scale), out.view = viewOf(out.u16, false, description);
  else if (dtype == "int16")
    convert(out.s16, src, offset, scale), out.view = viewOf(out.s16, false, description);
  else
    convert(out.f32, src, offset, scale), out.view = viewOf(out.f32, false, description);
}

std::vector<Channel> labelChannels(const GroundTruthVolumes& gt, const std::string& suffix) {
  std::vector<Channel> c{{"mask" + suffix, viewOf(gt.mask, true, "angiosynth vessel mask")},
                         {"centerline" + suffix, viewOf(gt.centerline, true, "angiosynth centreline")},
                         {"radius" + suffix, viewOf(gt.radius, false, "angiosynth radius (mm) on centreline")},
                         {"instances" + suffix, viewOf(gt.instances, true, "angiosynth segment id")}};
  if (!gt.classes.data.empty()) c.push_back({"classes" + suffix, viewOf(gt.classes, true, "angiosynth kind: 1 artery, 2 vein")});
  return c;
}

void writeChannels(const std::vector<Channel>& channels, const std::vector<std::string>& formats, const std::filesystem::path& dir, Json& files) {
  bool first = true;
  for (const auto& name : formats) {
    const VolumeFormat* format = findVolumeFormat(name);
    if (!format || format->kind != VolumeFormatKind::PerChannel) continue;
    for (const auto& c : channels) {
      const std::string file = c.role + std::string(format->extension);
      format->write(dir / file, c.view);
      files[first ? c.role : c.role + "_" + name] = file;
    }
    first = false;
  }
}

void writeMips(const Volume<float>& v, const Volume<std::uint8_t>* classes, double lo, double hi, const std::string& suffix,
               const std::filesystem::path& dir, Json& files) {
  const char* axes[] = {"mip_x", "mip_y", "mip_z"};
  for (int ax = 0; ax < 3; ++ax) {
    const std::string role = std::string(axes[ax]) + suffix;
    writePng(dir / (role + ".png"), classes ? maximumProjection(v, *classes, &classColour, ax, lo, hi) : maximumProjection(v, ax, lo, hi));
    files[role] = role + ".png";
  }
}

void writeGraphFiles(const VascularTree& tree, const std::vector<TreeInfo>& trees, const VolumeGrid& g, const std::vector<std::string>& graph_formats,
                     const std::string& suffix, const std::filesystem::path& dir, Json& files) {
  const auto file = [&](const std::string& stem, const std::string& ext, const std::string& role, auto&& write) {
    const std::string name = stem + suffix + ext;
    writeTextFile(dir / name, write);
    files[role + suffix] = name;
  };
  file("keypoints", ".csv", "keypoints", [&](std::ostream& o) { writeKeypoints(o, tree, trees, g); });
  for (const auto& name : graph_formats)
    if (const GraphFormat* format = findGraphFormat(name))
      for (const auto& f : format->files)
        file(std::string(f.stem), std::string(f.extension), std::string(f.role), [&](std::ostream& o) { f.write(o, tree, trees); });
}

}  // namespace angiosynth
