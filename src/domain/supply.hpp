#pragma once
// Lowers the demand around a newly perfused terminal (Hamarneh & Jassi 2010 §3.10, eq. 13) with VascuSynth's
// supply law: a voxel at distance d (map voxels) from the terminal is multiplied by
// 1 if d ≥ c_{K-1} (cut-off), else max(0, 1 − 1/Σ_i c_i dⁱ); d = 0 gives 0.
#include <cstdint>
#include <utility>
#include <vector>

#include "core/vec3.hpp"
#include "domain/demand_map.hpp"
#include "domain/demand_sampler.hpp"

namespace angiosynth {

double supplyFactor(const std::vector<double>& coefficients, double d);

// Applies the law around terminal t (mm) using the supply coefficients of t's voxel; touches
// only voxels within the cut-off.
void perfuse(const DemandMap& map, DemandSampler& sampler, const Vec3& terminal_mm, std::vector<std::pair<std::int64_t, double>>& scratch);

// The map's demand after perfusing `terminals_mm` in order: the same products in the same order
// per voxel as perfuse() one terminal at a time, so the same bits, computed in one pass over
// slabs of the map in parallel.
DemandSampler perfusedDemand(const DemandMap& map, const std::vector<Vec3>& terminals_mm);

// Brings a sampler perfused by one set of terminals to the bits perfusedDemand(map, terminals_mm)
// gives, at the cost of the neighbourhoods of `changed_mm` only: the terminals of either set not
// in the other (removed, moved, or new). The terminals both sets share must have perfused in the
// same relative order.
void reperfuse(const DemandMap& map, DemandSampler& sampler, const std::vector<Vec3>& changed_mm, const std::vector<Vec3>& terminals_mm);

}  // namespace angiosynth
