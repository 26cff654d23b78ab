#pragma once
// Method "cco": constrained constructive optimisation (Karch 1999; Kerautret et al., OpenCCO) in an
// analytic shape or a mask.
#include <filesystem>
#include <memory>

#include "domain/growth_domain.hpp"
#include "grow/common/domain_spec.hpp"
#include "grow/cco/decomposition.hpp"
#include "grow/cco/grower.hpp"
#include "grow/method.hpp"
#include "settings/schema.hpp"

namespace angiosynth {

// One tree of the forest: [[tree.inlet]], or [tree] itself for a single tree.
struct CcoInletSpec {
  std::string id = "tree";      // unique in the forest
  std::string kind = "artery";  // inlets of one kind compete for that kind's terminals
  RootSpec root;
  double share = 0;              // fixed share of its kind's terminals and flow; 0: the territory it wins
  double root_pressure = 0;      // Pa, at the root (a vein's outlet)
  double terminal_pressure = 0;  // Pa, at its terminals
  int line = 0;                  // of its table
};

struct CcoSetup final : GrowthSetup {
  std::string parameter_file;
  DomainSpec domain;
  CcoOptions cco;                         // everything but the roots, seed and sample
  CcoDecompositionOptions decomposition;  // [tree] parts (its `cco` is filled at growth)
  std::vector<CcoInletSpec> inlets;       // one per tree
  bool inlet_tables = false;              // the trees come from [[tree.inlet]] (else [tree] holds the one root)
  int terminals_line = 0;

  const char* method() const override { return "cco"; }
  nlohmann::ordered_json describe() const override;
  std::vector<std::filesystem::path> inputs() const override;
  std::unique_ptr<PreparedGrowth> prepare(std::uint64_t memory_limit) const override;
  const PhysicsParameters& physics() const override { return cco.physics; }
  std::int64_t terminals() const override { return cco.terminals; }
  std::vector<std::string> kinds() const override;
  double voxelMm() const override { return domain.voxel_mm; }
};

extern const GrowthMethod kCcoMethod;
// Its [tree] and [physics] settings (the inlets' tables are read beside them).
const std::vector<Setting<CcoOptions>>& ccoSettings();
const std::vector<Setting<PhysicsParameters>>& ccoPhysics();
const std::vector<Setting<CcoDecompositionOptions>>& ccoDecompositionSettings();

}  // namespace angiosynth
