// TOML parameter files: parsed, then every input they name read and checked as before growth.
#include "fuzz_support.hpp"
#include "config/scenario.hpp"
#include "pipeline/generate_sample.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  const auto file = fuzz::writeInput(data, size, "params.toml");
  return fuzz::expectOnlyInputErrors([&] { checkSampleInputs(readTomlParameters(file), fuzz::kMemoryLimit); });
}
