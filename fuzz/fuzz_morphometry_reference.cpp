// Morphometry references for `stats --compare`: the first byte picks the form (even: a reference
// TOML file; odd: a stats directory whose vessels.csv and bifurcations.csv are the rest), then
// the reference is compared with a small grown-like tree.
#include <filesystem>

#include "fuzz_support.hpp"
#include "morphometry/reference.hpp"

namespace {

// A parent splitting into two daughters and one of them again: bifurcations in two radius bands.
const angiosynth::Morphometry& smallTree() {
  static const angiosynth::Morphometry m = [] {
    angiosynth::VascularTree t;
    const auto root = t.addNode({0, 0, 0}, -1);
    const auto trunk = t.addNode({0, 0, 10}, root);
    const auto a = t.addNode({3, 0, 20}, trunk);
    t.addNode({-3, 0, 20}, trunk);
    t.addNode({5, 1, 25}, a);
    t.addNode({4, -2, 26}, a);
    const double radii[] = {0, 1.2, 0.9, 0.8, 0.07, 0.06};
    for (std::int32_t i = 0; i < t.nodeCount(); ++i) t.radius[std::size_t(i)] = radii[i];
    return angiosynth::measureTrees(t, {}, {});
  }();
  return m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  if (size == 0) return 0;
  std::string input;
  if (data[0] % 2 == 0) {
    input = fuzz::writeInput(data + 1, size - 1, "reference.toml").string();
  } else {
    const auto dir = fuzz::scratchDir() / "stats";
    std::filesystem::create_directories(dir);
    fuzz::writeInput(data + 1, size - 1, "stats/vessels.csv");
    fuzz::writeInput(data + 1, size - 1, "stats/bifurcations.csv");
    input = dir.string();
  }
  return fuzz::expectOnlyInputErrors([&] {
    const MorphometryReference ref = readMorphometryReference(input);
    const auto c = compareMorphometry(smallTree(), ref);
    (void)c.toJson().dump();
    (void)c.table();
  });
}
