#pragma once
// Method "lsystem" as read from a parameter file. Mode "lzh": Lázaro's closed network from
// high-level parameters (the block, the start and capillary vessels, the capillary spacing);
// mode "grammar": the stochastic vessel grammar (V-System) grown inside a domain.
#include <string>

#include "grow/common/domain_spec.hpp"
#include "grow/lsystem/grammar.hpp"
#include "grow/lsystem/lzh.hpp"
#include "grow/method.hpp"

namespace angiosynth {

struct LsystemSetup final : GrowthSetup {
  std::string parameter_file;
  bool grammar = false;  // the mode
  LzhParameters lzh;
  LzhPlan plan;                    // solved when the file is read: a bad block is a reading error
  GrammarOptions grammar_options;  // domain, root, direction, d0 and seed set by prepare() and grow()
  DomainSpec domain;               // grammar: where it grows
  RootSpec root;
  bool has_direction = false;
  Vec3 direction;
  double root_diameter_fraction = 0.02;  // of the domain's diameter: d0 when the file gives none
  int tree_line = 0;
  double voxel_mm = 0;
  PhysicsParameters physics_summary;

  const char* method() const override { return "lsystem"; }
  nlohmann::ordered_json describe() const override;
  std::vector<std::filesystem::path> inputs() const override { return grammar ? domainInputs(domain) : std::vector<std::filesystem::path>{}; }
  std::unique_ptr<PreparedGrowth> prepare(std::uint64_t memory_limit) const override;
  const PhysicsParameters& physics() const override { return physics_summary; }
  std::int64_t terminals() const override { return grammar ? std::int64_t(1) << grammar_options.iterations : plan.leaves; }
  std::vector<std::string> kinds() const override {
    return grammar ? std::vector<std::string>{"artery"} : std::vector<std::string>{"artery", "vein", "capillary"};
  }
  double voxelMm() const override { return voxel_mm; }
};

extern const GrowthMethod kLsystemMethod;

}  // namespace angiosynth
