// Mesh options as a [mesh] table of a parameter file (every key `angiosynth mesh` has a flag for),
// applied to a small tree with a junction, a taper and walls (the surface is built in full, no
// file is written). The tree is a few radii long and the sampling density is capped after
// reading (at most 3 grid steps across, a grid step of at least 0.25 mm, rings at least half a
// radius apart), so that a case stays small enough for long campaigns (docs/fuzzing.md).
#include <algorithm>
#include <sstream>

#include "fuzz_support.hpp"
#include "io/network_files.hpp"
#include "config/scenario.hpp"
#include "pipeline/mesh_outputs.hpp"

namespace {

const angiosynth::ExistingNetwork& smallTree() {
  static const angiosynth::ExistingNetwork net = [] {
    const auto dir = angiosynth::fuzz::scratchDir();
    std::ofstream(dir / "mesh_nodes.csv") << "id,pos_x,pos_y,pos_z\n0,0,0,0\n1,2,0,0\n2,3.6,1.2,0\n3,3.6,-1.2,0.4\n";
    std::ofstream(dir / "mesh_edges.csv") << "id,node1id,node2id,radius,radius_start,wall_start,wall\n"
                                             "1,0,1,0.5,0.55,0.1,0.1\n2,1,2,0.4,0.4,0.08,0.07\n3,1,3,0.35,0.4,0.08,0.06\n";
    return angiosynth::readNetwork(dir / "mesh_edges.csv");
  }();
  return net;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  const auto params = fuzz::scratchDir() / "mesh.toml";
  std::ofstream(params) << "[domain]\nshape = \"disc\"\nradius = \"10 mm\"\nvoxel_size = \"0.1 mm\"\n[tree]\nmethod = \"cco\"\nterminals = 2\n"
                           "[physics]\nperfusion_flow = \"1 mL/min\"\n[mesh]\n"
                        << std::string_view(reinterpret_cast<const char*>(data), size) << "\n";
  const auto out = fuzz::scratchDir() / "mesh_out";
  std::filesystem::create_directories(out);
  return fuzz::expectOnlyInputErrors([&] {
    Scenario sc = readTomlParameters(params);
    sc.mesh.formats = {};
    sc.mesh.samples_across = std::min(sc.mesh.samples_across.value_or(4), 3);
    if (sc.mesh.voxel_mm) sc.mesh.voxel_mm = std::max(*sc.mesh.voxel_mm, 0.25);
    if (sc.mesh.ring_spacing) sc.mesh.ring_spacing = std::max(*sc.mesh.ring_spacing, 0.5);
    writeSurfaceFiles(smallTree().tree, sc.mesh, fuzz::kMemoryLimit, out, {}, {}, smallTree().ids);
  });
}
