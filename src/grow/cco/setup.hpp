#pragma once
// Method "cco": constrained constructive optimisation (Karch 1999 / OpenCCO, seed 000) in an
// analytic shape or a mask.
#include <filesystem>
#include <memory>

#include "domain/growth_domain.hpp"
#include "grow/cco/grower.hpp"
#include "grow/method.hpp"

namespace angiosynth {

// The domain of method "cco": an analytic shape or a mask file.
struct CcoDomainSpec {
  DomainShape shape = DomainShape::Sphere;
  double size_mm = 0;            // radius (sphere, disc) or side (cube, square)
  std::filesystem::path mask;    // shape mask: NIfTI (.nii, .nii.gz) or a VascuSynth box map
  bool demand_weighted = false;  // sampling = "demand": terminals drawn ∝ mask value
  double voxel_mm = 0;           // analytic shapes and box maps; a NIfTI mask carries its own
  int line = 0;                  // of [domain]
};

// Where a tree enters the domain, as the file gives it.
struct CcoRootSpec {
  bool has_root_offset = false;  // analytic shapes: root = centre + offset (default: the top, +y)
  Vec3 root_offset_mm;
  bool root_in_mm = false;       // masks: `root` (mm in the frame) rather than root_voxel
  Vec3 root_mm;
  Vec3 root_voxel;               // masks: the root in mask voxels
  int root_line = 0;
};

// One tree of the forest: [[tree.inlet]], or [tree] itself for a single tree.
struct CcoInletSpec {
  std::string id = "tree";       // unique in the forest
  std::string kind = "artery";   // inlets of one kind compete for that kind's terminals
  CcoRootSpec root;
  double share = 0;              // fixed share of its kind's terminals and flow; 0: the territory it wins
  double root_pressure = 0;      // Pa, at the root (a vein's outlet)
  double terminal_pressure = 0;  // Pa, at its terminals
  int line = 0;                  // of its table
};

struct CcoSetup final : GrowthSetup {
  std::string parameter_file;
  CcoDomainSpec domain;
  CcoOptions cco;          // everything but the roots, seed and sample
  std::vector<CcoInletSpec> inlets;  // one per tree
  bool inlet_tables = false;         // the trees come from [[tree.inlet]] (else [tree] holds the one root)
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

// The growth domain of a cco setup: the analytic shape on its voxel frame, a NIfTI mask, or a
// VascuSynth box map; checks the memory before allocating.
GrowthDomain loadCcoDomain(const CcoSetup& s, std::uint64_t memory_limit_bytes);
// An inlet's root in the domain's frame (mm): the offset from the centre for analytic shapes.
Vec3 ccoRoot(const CcoSetup& s, const CcoRootSpec& root, const GrowthDomain& d);

}  // namespace angiosynth
