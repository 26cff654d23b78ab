#pragma once
// Domain files of the growth methods: NIfTI masks, and the memory a voxel domain needs.
#include <cstdint>
#include <filesystem>

#include "domain/growth_domain.hpp"
#include <string>

#include "domain/demand_map.hpp"

namespace angiosynth {

// Refuses a domain of `voxels` voxels (mask, depth, sampler) that would need more than limit bytes.
void checkDomainMemory(std::int64_t voxels, std::uint64_t limit, const std::string& file, int line, const std::string& what);
bool isNifti(const std::filesystem::path& p);
// A NIfTI-1 volume as a map of values (voxel > 0 = inside); its voxels must be isotropic.
DemandMap readNiftiMask(const std::filesystem::path& file, std::uint64_t memory_limit_bytes);

}  // namespace angiosynth
