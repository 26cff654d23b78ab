#pragma once
// Grows the forest of a TOML parameter file (any method; `setup` is set for dcco), for tests
// that need a real tree.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>

#include "grow/dcco/setup.hpp"
#include "config/scenario.hpp"

namespace angiosynth::test {

struct Grown {
  std::shared_ptr<const GrowthSetup> growth;
  std::unique_ptr<PreparedGrowth> prepared;
  Forest forest;
  const DccoSetup* setup = nullptr;
};

inline Grown growFile(const std::filesystem::path& file, std::uint64_t seed = 1, GrowthReport* out = nullptr) {
  Grown g;
  g.growth = readTomlParameters(file).growth;
  g.setup = dynamic_cast<const DccoSetup*>(g.growth.get());
  g.prepared = g.growth->prepare(std::uint64_t(1) << 40);
  g.prepared->checkFeasibility();
  GrowthReport report;
  g.forest = g.prepared->grow(seed, 0, report, {});
  if (out) *out = report;
  return g;
}

}  // namespace angiosynth::test
