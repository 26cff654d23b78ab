// Existing networks ([initial] file): the same bytes read as VItA's .cco and as SWC.
#include "fuzz_support.hpp"
#include "io/network_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  for (const char* name : {"tree.cco", "tree.swc"}) {
    const auto file = fuzz::writeInput(data, size, name);
    fuzz::expectOnlyInputErrors([&] { readNetwork(file); });
  }
  return 0;
}
