// Dataset specs: read (which resolves sample 0), then the first samples' draws and parameters.
#include "dataset/spec.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  const auto file = fuzz::writeInput(data, size, "spec.toml");
  return fuzz::expectOnlyInputErrors([&] {
    const DatasetSpec spec = readDatasetSpec(file);
    std::vector<std::int64_t> first;
    for (std::int64_t i = 0; i < std::min<std::int64_t>(spec.samples, 4); ++i) first.push_back(i);
    checkSampleDraws(spec, first);
  });
}
