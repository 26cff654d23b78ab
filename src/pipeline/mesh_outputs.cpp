#include "pipeline/mesh_outputs.hpp"

#include <fstream>
#include <stdexcept>

#include "io/mesh_writers.hpp"
#include "mesh/vessel_surface.hpp"

namespace angiosynth {

using Json = nlohmann::ordered_json;

SurfaceFiles writeSurfaceFiles(const VascularTree& tree, const MeshParameters& p, std::uint64_t memory_limit, const std::filesystem::path& dir,
                               const std::function<void(std::int64_t, std::int64_t)>& progress) {
  SurfaceOptions o;
  o.voxel_mm = p.voxel_mm;
  o.samples_across = p.samples_across;
  o.adaptive = !p.uniform;
  o.restore_volume = !p.on_surface;
  o.memory_limit = memory_limit;
  SurfaceReport report;
  const auto mesh = vesselSurface(tree, o, &report, progress);
  const auto topo = meshTopology(mesh);
  SurfaceFiles out;
  out.files = Json::object();
  for (const auto& f : p.formats) {
    const std::string name = "surface." + f;
    std::ofstream os(dir / name, std::ios::binary);
    meshWriter(f)(os, mesh);
    if (!os) throw std::runtime_error("cannot write " + (dir / name).string());
    out.files[f] = name;
  }
  std::int64_t trees = 0, segments = 0;
  for (std::int32_t i = 0; i < tree.nodeCount(); ++i) trees += tree.isRoot(i), segments += !tree.isRoot(i) && !tree.isLink(i);
  out.parameters = {{"formats", p.formats},
                    {"voxel_mm", p.voxel_mm > 0 ? Json(p.voxel_mm) : Json(nullptr)},
                    {"samples_across", p.samples_across},
                    {"adaptive", !p.uniform},
                    {"volume_restored", !p.on_surface},
                    {"method", "marching tetrahedra of the signed distance to the union of each tree's capsules and round cones, on a "
                               "2:1-balanced octree of cells sized to each vessel's radius, split into conforming tetrahedra"}};
  out.statistics = {{"trees", trees},
                    {"segments", segments},
                    {"vertices", mesh.vertices.size()},
                    {"triangles", mesh.triangles.size()},
                    {"triangles_per_segment", segments > 0 ? double(mesh.triangles.size()) / double(segments) : 0.0},
                    {"finest_step_mm", report.voxel_mm},
                    {"coarsest_cell_mm", report.coarsest_mm},
                    {"levels", report.levels},
                    {"cells", report.cells},
                    {"largest_volume_move_mm", report.largest_volume_move_mm},
                    {"estimated_bytes", report.estimated_bytes},
                    {"enclosed_volume_mm3", topo.volume_mm3},
                    {"boundary_edges", topo.boundary_edges},
                    {"nonmanifold_edges", topo.nonmanifold_edges},
                    {"misoriented_edges", topo.misoriented_edges},
                    {"degenerate_triangles", topo.degenerate_triangles},
                    {"cavities_removed", report.cavities_removed},
                    {"tree_components", topo.tree_components},
                    {"tree_euler_characteristic", topo.tree_euler}};
  return out;
}

}  // namespace angiosynth
