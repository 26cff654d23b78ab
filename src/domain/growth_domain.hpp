#pragma once
// The region a CCO tree perfuses (Kerautret et al. (OpenCCO) §2.1, §3.3): a sphere, cube, disc or square given
// analytically, or a voxel mask. Every domain also carries the voxel frame the rest of the
// pipeline works in (a DemandMap whose demand is the sampling weight, 0 outside), so CCO and
// VascuSynth growth share one domain model. Disc, square and one-slice masks are 2D: the tree
// lies in the plane z = plane_z and CCO's scaling laws use d = 2.
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/rng.hpp"
#include "domain/demand_map.hpp"
#include "domain/demand_sampler.hpp"

namespace angiosynth {

enum class DomainShape { Sphere, Cube, Disc, Square, Mask };
const char* domainShapeName(DomainShape s);

class GrowthDomain {
 public:
  // Analytic shapes centred in a voxel frame of the given voxel size, with `margin_voxels`
  // empty voxels around them. `size` is the radius (sphere, disc) or the side (cube, square).
  static GrowthDomain analytic(DomainShape shape, double size_mm, double voxel_mm, int margin_voxels = 2);
  // The voxel frame `analytic` builds, known before anything is allocated.
  static std::array<std::int32_t, 3> analyticDims(DomainShape shape, double size_mm, double voxel_mm, int margin_voxels = 2);
  // A mask: voxels with weight > 0 are inside. Depth comes from the exact Euclidean distance
  // between voxel centres of the two sides (less half a voxel), interpolated trilinearly and
  // never positive in a voxel outside the mask. `demand_weighted`: terminals are drawn ∝
  // weight, else uniformly.
  static GrowthDomain mask(DemandMap map, bool demand_weighted);

  DomainShape shape() const { return shape_; }
  int dimension() const { return dimension_; }
  double measure() const { return measure_; }  // mm² (2D) or mm³ (3D)
  // (V/n)^(1/d): the spacing of n terminals spread evenly over the domain (δ_max of Kerautret
  // et al. (OpenCCO) eq. 15).
  double terminalSpacing(std::int64_t n) const { return std::pow(measure_ / double(n), 1.0 / dimension_); }
  const DemandMap& frame() const { return map_; }
  Vec3 lo() const { return Vec3(0, 0, 0); }
  Vec3 hi() const { return map_.extentMm(); }
  Vec3 center() const { return center_; }
  double size() const { return size_; }
  double planeZ() const { return center_.z; }
  bool demandWeighted() const { return demand_weighted_; }

  // Distance from p to the domain border in mm, positive inside.
  double depth(const Vec3& p) const;
  // True if the capsule a–b of radius r lies inside. A capsule that starts at the root (which
  // may sit on the border, where the vessel enters) need only keep its centreline inside near
  // the root: at distance d from it the required depth is min(r, d − r).
  bool capsuleInside(const Vec3& a, const Vec3& b, double r, bool starts_at_root) const;
  // A point drawn uniformly in the domain (∝ weight when demand-weighted).
  Vec3 sample(Rng& rng) const;
  // The factor on δ_max at p: (mean weight / weight at p)^(1/d) when demand-weighted, so that
  // terminals are as much denser where demand is higher as sampling makes them; else 1.
  double spacingScale(const Vec3& p) const;
  // A root on the border: the domain's top (+y) point for analytic shapes.
  Vec3 defaultRoot() const;

 private:
  double maskDepth(const Vec3& p) const;

  DomainShape shape_ = DomainShape::Sphere;
  int dimension_ = 3;
  double measure_ = 0;
  DemandMap map_;
  Vec3 center_;
  double size_ = 0;  // radius, or half the side
  bool demand_weighted_ = false;
  double mean_weight_ = 1;
  std::vector<float> depth_;                                 // masks: depth at voxel centres, mm
  std::shared_ptr<const DemandSampler> sampler_;             // demand-weighted masks
  std::shared_ptr<const std::vector<std::int64_t>> inside_;  // uniform masks: their voxels in order
};

// Depth (mm, positive inside) at every voxel centre of a mask with weight > 0 inside; voxels
// outside the map count as outside. One-slice maps get 2D distances. Exact Euclidean distance transform.
std::vector<float> maskDepthMap(const DemandMap& map);

}  // namespace angiosynth
