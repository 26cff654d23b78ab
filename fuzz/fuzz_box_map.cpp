// VascuSynth box maps: the demand map, then the same bytes as a supply map beside a 2x2x2 demand map.
#include "fuzz_support.hpp"
#include "io/map_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  const auto file = fuzz::writeInput(data, size, "map.txt");
  BoxMapSpec sc;
  sc.parameter_file = "fuzz.toml";
  sc.voxel_mm = 1;
  sc.demand_map = file;
  fuzz::expectOnlyInputErrors([&] { loadDomain(sc, fuzz::kMemoryLimit); });
  const auto demand = fuzz::scratchDir() / "demand2.txt";
  std::ofstream(demand) << "2 2 2\n0 0 0 2 2 2\n1\n";
  sc.demand_map = demand;
  sc.supply_map = file;
  return fuzz::expectOnlyInputErrors([&] { loadDomain(sc, fuzz::kMemoryLimit); });
}
