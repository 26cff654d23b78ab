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
  bool has_root_offset = false;  // analytic shapes: root = centre + offset (default: the top, +y)
  Vec3 root_offset_mm;
  bool root_in_mm = false;       // masks: `root` (mm in the frame) rather than root_voxel
  Vec3 root_mm;
  Vec3 root_voxel;               // masks: the root in mask voxels
  int root_line = 0;
  double voxel_mm = 0;           // analytic shapes and box maps; a NIfTI mask carries its own
  int line = 0;                  // of [domain]
};

struct CcoSetup final : GrowthSetup {
  std::string parameter_file;
  CcoDomainSpec domain;
  CcoOptions cco;          // everything but the root, seed and sample
  int terminals_line = 0;

  const char* method() const override { return "cco"; }
  nlohmann::ordered_json describe() const override;
  std::vector<std::filesystem::path> inputs() const override;
  std::unique_ptr<PreparedGrowth> prepare(std::uint64_t memory_limit) const override;
  const PhysicsParameters& physics() const override { return cco.physics; }
  std::int64_t terminals() const override { return cco.terminals; }
  double voxelMm() const override { return domain.voxel_mm; }
};

extern const GrowthMethod kCcoMethod;

// The growth domain of a cco setup: the analytic shape on its voxel frame, a NIfTI mask, or a
// VascuSynth box map; checks the memory before allocating.
GrowthDomain loadCcoDomain(const CcoSetup& s, std::uint64_t memory_limit_bytes);
// The root in the domain's frame (mm): the offset from the centre for analytic shapes.
Vec3 ccoRoot(const CcoSetup& s, const GrowthDomain& d);

}  // namespace angiosynth
