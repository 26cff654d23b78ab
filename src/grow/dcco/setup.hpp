#pragma once
// Method "dcco": domain-constrained CCO in stages (Maso Talou et al. 2021).
#include <memory>
#include <string>
#include <vector>

#include "grow/common/domain_spec.hpp"
#include "grow/dcco/grower.hpp"
#include "grow/common/regions.hpp"
#include "grow/method.hpp"
#include "io/network_files.hpp"

namespace angiosynth {

// One [[stage]] as the file gives it: its parameters and the names of its regions.
struct DccoStageSpec {
  DccoStage stage;                     // domain pointers are set when the domain is prepared
  std::vector<std::string> domain;     // region names (empty: the whole [domain])
  std::vector<std::string> avascular;  // no vessel enters
  std::vector<std::string> carriage;   // vessels pass, no terminal lies there
  int line = 0;
};

struct DccoSetup final : GrowthSetup {
  std::string parameter_file;
  DomainSpec domain;
  RootSpec root;
  std::string kind = "artery";
  DccoOptions options;  // root, world, stages, seed are set per sample
  std::vector<RegionSpec> regions;
  std::vector<DccoStageSpec> stages;
  PhysicsParameters physics_summary;  // γ of the first stage, η, Q: for the statistics
  // [initial]: the network growth continues (empty path: none); positions relative to the
  // domain's centre or its grid's corner, branching, role and outflow as the file and [[initial.vessel]] set them.
  std::filesystem::path initial_file;
  ExistingNetwork initial;
  bool initial_from_corner = false;  // [initial] origin = "corner": positions as angiosynth's graphs give them
  std::vector<double> root_radii;    // per root of the initial network

  const char* method() const override { return "dcco"; }
  nlohmann::ordered_json describe() const override;
  std::vector<std::filesystem::path> inputs() const override;
  std::unique_ptr<PreparedGrowth> prepare(std::uint64_t memory_limit) const override;
  const PhysicsParameters& physics() const override { return physics_summary; }
  std::int64_t terminals() const override;
  std::vector<std::string> kinds() const override { return {kind}; }
  double voxelMm() const override { return domain.voxel_mm; }
};

extern const GrowthMethod kDccoMethod;

}  // namespace angiosynth
