#pragma once
// VascuSynth's box-format oxygen-demand and supply maps (vascusynth_behaviour.md).
#include <cstdint>
#include <filesystem>

#include "domain/demand_map.hpp"
#include "io/scenario.hpp"

namespace angiosynth {

// Reads the demand map (and supply map or coefficients) of a scenario and checks its root:
// inside the map and on non-zero demand. Refuses maps whose working memory would exceed
// memory_limit_bytes, before allocating.
DemandMap loadDomain(const Scenario& sc, std::uint64_t memory_limit_bytes);

// Bytes the growth stage needs per map voxel (demand, supply index, sampler).
std::uint64_t growthBytesFor(std::int64_t voxels);

}  // namespace angiosynth
