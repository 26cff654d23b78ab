#pragma once
// VascuSynth's box-format oxygen-demand and supply maps (vascusynth_behaviour.md).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "domain/demand_map.hpp"
#include "core/vec3.hpp"

namespace angiosynth {

// A box-map domain as a parameter file names it.
struct BoxMapSpec {
  std::string parameter_file;  // where the root was given, for errors
  std::filesystem::path demand_map;
  std::filesystem::path supply_map;  // empty: supply_coefficients everywhere
  std::vector<double> supply_coefficients{0.65, 0.34, 0.01, 7};
  int supply_line = 0;
  double voxel_mm = 0;
  Vec3 root_voxel;  // map-voxel coordinates
  int root_line = 0;
};

// Reads the demand map (and supply map or coefficients) and checks the root: inside the map
// and on non-zero demand. Refuses maps whose working memory would exceed memory_limit_bytes,
// before allocating.
DemandMap loadDomain(const BoxMapSpec& sc, std::uint64_t memory_limit_bytes);

// Bytes the growth stage needs per map voxel (demand, supply index, clearance, sampler).
std::uint64_t growthBytesFor(std::int64_t voxels);

}  // namespace angiosynth
