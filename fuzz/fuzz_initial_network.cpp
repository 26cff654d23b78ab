// Graph files as the [initial] network growth continues: the same bytes read as each of the
// five formats, then grown on by 4 DCCO terminals in a disc, or by space colonisation in a disc
// for a few steps (the first byte picks), through the parameter reader as a user's file is.
// DCCO is sized so that a network no terminal can join is refused in a few seconds under the
// sanitizers: its spacing relaxes after 3 failed draws, not 100 (refused after 300 draws, not
// 10,000), and each draw costs at most 8 candidate vessels at 7 lattice points each. A crowded
// network can make every trial of every draw reach the exact checks after its commit.
#include "fuzz_sample.hpp"
#include "io/network_files.hpp"

namespace {

std::string parameters(bool dcco, const std::string& network) {
  const std::string domain = "seed = 1\n[domain]\nshape = \"disc\"\nradius = \"10 mm\"\nvoxel_size = \"0.2 mm\"\n";
  if (dcco)
    return domain + "[tree]\nmethod = \"dcco\"\nroot_radius = \"0.2 mm\"\n[initial]\nfile = \"" + network +
           "\"\nbranching = \"versatile\"\nrole = \"distribution\"\n[physics]\nperfusion_flow = \"0.3 mL/min\"\n[[stage]]\nterminals = "
           "4\ndraws_before_relaxing = 3\nlattice = 4\nmax_candidates = 8\n"
           "[image]\nformats = []\ngraph_formats = []\n";
  return domain + "[tree]\nmethod = \"colonisation\"\nveins = false\n[initial]\nfile = \"" + network +
         "\"\n[[stage]]\nsteps = 8\ndrains_per_step = 100\n[image]\nformats = []\ngraph_formats = []\n";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  if (size == 0) return 0;
  const bool dcco = data[0] % 2 == 0;
  const auto out = fuzz::scratchDir() / "initial";
  for (const char* name : {"tree.cco", "tree.swc", "tree.gxl", "tree.vtp", "tree_nodes.csv"}) {
    fuzz::writeInput(data + 1, size - 1, name);
    if (std::string(name) == "tree_nodes.csv") fuzz::writeInput(data + 1, size - 1, "tree_edges.csv");
    const auto params = fuzz::scratchDir() / "initial.toml";
    std::ofstream(params) << parameters(dcco, name);
    fuzz::expectOnlyInputErrors([&] {
      // Networks of up to 32 nodes are grown on (the reader is fuzz_network_file's for any size;
      // growth under the sanitizers costs seconds for a few hundred nodes).
      if (readNetwork(fuzz::scratchDir() / name, 1, fuzz::kMemoryLimit).tree.nodeCount() > 32) return;
      fuzz::growParameterFile(params, out);
    });
  }
  return 0;
}
