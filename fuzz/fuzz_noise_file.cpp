// VascuSynth noise files, then applied to a small sample (so the drawn values are used).
#include "fuzz_sample.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  const auto file = fuzz::writeInput(data, size, "noise.txt");
  return fuzz::expectOnlyInputErrors([&] { fuzz::degradeSmallSample(readVascuSynthNoiseFile(file)); });
}
