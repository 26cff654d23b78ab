#pragma once
// Method "colonisation": space colonisation of arterial and venous trees (Rauch & Harders 2021) in an
// analytic shape or a mask, in stages with their own parameters and regions.
#include <optional>
#include <filesystem>
#include <map>
#include <memory>

#include "grow/colonisation/grower.hpp"
#include "grow/common/domain_spec.hpp"
#include "grow/common/regions.hpp"
#include "grow/method.hpp"
#include "io/network_files.hpp"

namespace angiosynth {

// A length as the file gives it: mm, or (absent) a fraction of the domain's diameter.
struct ColonisationStageSpec {
  ColonisationStage stage;  // lengths filled in by prepare()
  // The lengths as the file gives them (mm); unset: their declared share of the domain's diameter.
  std::optional<double> step, perception_distance, satisfaction_distance, co2_distance, drain_spacing, terminal_radius, surface_depth;
  std::vector<std::string> domain;  // regions its drains come from (empty: the whole domain)
  int line = 0;
  std::map<std::string, int> lines;  // the lines of keys checked against the domain once it is loaded
};

struct ColonisationRootSpec {
  std::string id, kind = "artery";
  RootSpec root;
  bool has_direction = false;
  bool beside_artery = false;  // the default vein: beside the artery's root
  Vec3 direction;
  int line = 0;
};

struct ColonisationSetup final : GrowthSetup {
  std::string parameter_file;
  DomainSpec domain;
  ColonisationOptions options;  // stages, roots, world set by prepare() and grow()
  std::vector<ColonisationStageSpec> stages;
  std::vector<ColonisationRootSpec> roots;
  std::vector<RegionSpec> regions;
  std::vector<std::string> avascular;  // regions no vessel enters
  // [initial]: stumps of an existing network (each root a tree of `initial_kind`) that grow on.
  std::filesystem::path initial_file;
  ExistingNetwork initial;
  bool initial_from_corner = false;
  std::string initial_kind = "artery";
  PhysicsParameters physics_summary;  // κ, η, pressures and flow: flows and pressures of the trees

  const char* method() const override { return "colonisation"; }
  nlohmann::ordered_json describe() const override;
  std::vector<std::filesystem::path> inputs() const override { return domainInputs(domain); }
  std::unique_ptr<PreparedGrowth> prepare(std::uint64_t memory_limit) const override;
  const PhysicsParameters& physics() const override { return physics_summary; }
  std::int64_t terminals() const override { return 0; }  // leaves are an outcome, not a parameter
  std::vector<std::string> kinds() const override;
  double voxelMm() const override { return domain.voxel_mm; }
};

extern const GrowthMethod kColonisationMethod;

}  // namespace angiosynth
