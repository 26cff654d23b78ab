#pragma once
// Method "vascusynth": VascuSynth's oxygen-demand CCO on box maps (Hamarneh & Jassi 2010), as read from a
// TOML file or from VascuSynth's own parameter files.
#include <memory>

#include "grow/method.hpp"
#include "grow/vascusynth/grower.hpp"
#include "io/map_files.hpp"

namespace angiosynth {

struct VascuSynthSetup final : GrowthSetup {
  BoxMapSpec domain;       // demand and supply maps, voxel size, root (map voxels)
  GrowthOptions growth;    // root_mm and seed are set per sample
  int terminals_line = 0;  // of the terminal count, for feasibility errors

  const char* method() const override { return "vascusynth"; }
  nlohmann::ordered_json describe() const override;
  std::vector<std::filesystem::path> inputs() const override;
  std::unique_ptr<PreparedGrowth> prepare(std::uint64_t memory_limit) const override;
  const PhysicsParameters& physics() const override { return growth.physics; }
  std::int64_t terminals() const override { return growth.terminals; }
  std::vector<std::string> kinds() const override { return {"artery"}; }  // VascuSynth grows one arterial tree
  double voxelMm() const override { return domain.voxel_mm; }
};

extern const GrowthMethod kVascuSynthMethod;

}  // namespace angiosynth
