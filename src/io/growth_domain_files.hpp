#pragma once
// Builds the growth domain of a "cco" scenario: an analytic shape on its voxel frame, a NIfTI
// mask, or a VascuSynth box map; checks the root and the memory before allocating.
#include <cstdint>
#include <filesystem>

#include "domain/growth_domain.hpp"
#include "io/scenario.hpp"

namespace angiosynth {

GrowthDomain loadGrowthDomain(const Scenario& sc, std::uint64_t memory_limit_bytes);
// The root in the domain's frame (mm): the offset from the centre for analytic shapes.
Vec3 ccoRoot(const Scenario& sc, const GrowthDomain& d);
// A NIfTI-1 volume as a map of values (voxel > 0 = inside); its voxels must be isotropic.
DemandMap readNiftiMask(const std::filesystem::path& file, std::uint64_t memory_limit_bytes);

}  // namespace angiosynth
