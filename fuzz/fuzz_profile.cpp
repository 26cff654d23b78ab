// Degradation profiles (TOML), then applied to a small sample (so every effect's sizes are used).
#include "fuzz_sample.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  const auto file = fuzz::writeInput(data, size, "profile.toml");
  return fuzz::expectOnlyInputErrors([&] { fuzz::degradeSmallSample(readProfileToml(file)); });
}
