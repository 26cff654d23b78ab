// VascuSynth parameter files (KEY: value lines).
#include "fuzz_support.hpp"
#include "config/scenario.hpp"
#include "pipeline/generate_sample.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  const auto file = fuzz::writeInput(data, size, "params.txt");
  return fuzz::expectOnlyInputErrors([&] { checkSampleInputs(readVascuSynthParameters(file), fuzz::kMemoryLimit); });
}
