#include "pipeline/vascusynth_layout.hpp"

#include <cstdio>

#include "files/text_file.hpp"
#include "io/volume_writers.hpp"
#include "pipeline/volume_outputs.hpp"

namespace angiosynth {

VolumeGrid vascusynthGrid(const DemandMap& map, double output_voxel_mm, const std::string& file, int line) {
  VolumeGrid g;
  for (int ax = 0; ax < 3; ++ax) g.dims[ax] = axisVoxels(std::floor(map.dims[ax] * map.voxel_mm / output_voxel_mm + 1e-9) + 1, file, line);
  g.spacing_mm = Vec3(output_voxel_mm, output_voxel_mm, output_voxel_mm);
  g.origin_mm = Vec3(0, 0, 0);
  return g;
}

void writeVascuSynthGraphs(const Forest& forest, const GraphFrame& frame, const std::string& graph_id, const std::filesystem::path& dir,
                           nlohmann::ordered_json& files) {
  writeTextFile(dir / "tree_structure.xml", [&](std::ostream& o) { writeVascuSynthGxl(o, forest.vessels, frame, graph_id); });
  files["gxl"] = "tree_structure.xml";
  writeTextFile(dir / "tree.dot", [&](std::ostream& o) { writeDot(o, forest.vessels, forest.trees, frame); });
  files["dot"] = "tree.dot";
}

void writeVascuSynthSlices(const VolumeView& image, const Volume<float>& shown, double lo, double hi, const std::string& sub,
                           const VascuSynthLayout& layout, const std::filesystem::path& dir, nlohmann::ordered_json& files) {
  const bool png = layout.slice_format == "png";
  std::filesystem::create_directories(dir / sub);
  writeNifti(dir / sub / "image.nii.gz", image);
  files[sub] = sub + "/image.nii.gz";
  for (std::int32_t z = 0; z < shown.grid.dims[2]; ++z) {
    char name[32];
    std::snprintf(name, sizeof name, "image%03d.%s", z, png ? "png" : "jpg");
    if (png)
      writePng(dir / sub / name, sliceZ(shown, z, lo, hi));
    else
      writeJpeg(dir / sub / name, sliceZ(shown, z, lo, hi));
  }
  files[sub + "_slices"] = sub + "/image%03d." + (png ? "png" : "jpg");
}

}  // namespace angiosynth
