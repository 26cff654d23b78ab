// Graph files through `mesh`: the same bytes read as each of the five formats (VItA's .cco,
// SWC, GXL, VTP, the CSV pair), then meshed with the default tubes under a small memory limit
// (the surface is built in full, no file is written); networks of up to 24 nodes are meshed, under
// a limit of 1 MiB (about 16,000 triangles), so that a long campaign stays at many cases a second
// (docs/fuzzing.md).
#include "fuzz_support.hpp"
#include "io/network_files.hpp"
#include "pipeline/mesh_outputs.hpp"

constexpr std::uint64_t kMeshMemoryLimit = 1ull << 20;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  const auto out = fuzz::scratchDir() / "mesh";
  std::filesystem::create_directories(out);
  for (const char* name : {"tree.cco", "tree.swc", "tree.gxl", "tree.vtp", "tree_nodes.csv"}) {
    const auto file = fuzz::writeInput(data, size, name);
    if (std::string(name) == "tree_nodes.csv") fuzz::writeInput(data, size, "tree_edges.csv");
    fuzz::expectOnlyInputErrors([&] {
      const auto net = readNetwork(file, 1, fuzz::kMemoryLimit);
      // Small networks are meshed (each vessel is tubes and contoured joints: the mesher's cost
      // grows with them and the reader is fuzzed for any size).
      if (net.tree.nodeCount() > 24) return;
      MeshParameters p;
      p.formats = {};
      writeSurfaceFiles(net.tree, p, kMeshMemoryLimit, out, {}, {}, net.ids);
    });
  }
  return 0;
}
