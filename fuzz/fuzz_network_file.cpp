// Existing networks ([initial] file): the same bytes read as VItA's .cco, SWC, GXL, VTP (ascii,
// base64, zlib, appended raw) and as both files of a CSV pair.
#include "fuzz_support.hpp"
#include "io/network_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  for (const char* name : {"tree.cco", "tree.swc", "tree.gxl", "tree.vtp", "tree_nodes.csv"}) {
    const auto file = fuzz::writeInput(data, size, name);
    if (std::string(name) == "tree_nodes.csv") fuzz::writeInput(data, size, "tree_edges.csv");
    fuzz::expectOnlyInputErrors([&] { readNetwork(file); });
  }
  return 0;
}
