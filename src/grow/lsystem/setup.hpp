#pragma once
// Method "lsystem" as read from a parameter file. Mode "lzh": seed 004's closed network from
// high-level parameters (the block, the start and capillary vessels, the capillary spacing).
#include <string>

#include "grow/lsystem/lzh.hpp"
#include "grow/method.hpp"

namespace angiosynth {

struct LsystemSetup final : GrowthSetup {
  std::string parameter_file;
  LzhParameters lzh;
  LzhPlan plan;               // solved when the file is read: a bad block is a reading error
  double voxel_mm = 0;
  PhysicsParameters physics_summary;

  const char* method() const override { return "lsystem"; }
  nlohmann::ordered_json describe() const override;
  std::vector<std::filesystem::path> inputs() const override { return {}; }
  std::unique_ptr<PreparedGrowth> prepare(std::uint64_t memory_limit) const override;
  const PhysicsParameters& physics() const override { return physics_summary; }
  std::int64_t terminals() const override { return plan.leaves; }
  std::vector<std::string> kinds() const override { return {"artery", "vein", "capillary"}; }
  double voxelMm() const override { return voxel_mm; }
};

extern const GrowthMethod kLsystemMethod;

}  // namespace angiosynth
