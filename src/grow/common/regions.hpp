#pragma once
// Named regions of a domain (Maso Talou et al. 2021 §1.1.5–1.1.6; staged colonisation too): analytic shapes placed relative to the
// domain's centre. A stage's domain is the union of some regions (or the whole domain), minus its
// avascular regions (no vessel enters) and, for terminals, its carriage regions (vessels pass,
// no terminal lies there). Unions are rasterised on the domain's voxel frame and get a distance
// map there (GrowthDomain::mask), so a vessel may cross the seam between two regions of a union.
#include <string>
#include <vector>

#include "domain/growth_domain.hpp"

namespace angiosynth {

enum class RegionShape { Sphere, Disc, Shell, Annulus, Box };
const char* regionShapeName(RegionShape s);

struct RegionSpec {
  std::string name;
  RegionShape shape = RegionShape::Sphere;
  Vec3 centre;                  // mm from the domain's centre
  double radius = 0;            // sphere, disc
  double inner = 0, outer = 0;  // shell, annulus
  Vec3 size;                    // box: sides, mm
  int line = 0;
};

// Signed distance from p (mm in the frame) to the region's border, positive inside; disc and
// annulus ignore z.
double regionDepth(const RegionSpec& r, const Vec3& p, const Vec3& domain_centre);
// The regions of `all` with the given names, in their order (every name must be defined).
std::vector<const RegionSpec*> regionsNamed(const std::vector<RegionSpec>& all, const std::vector<std::string>& names);
// Area (2D) or volume of the region, mm² or mm³.
double regionMeasure(const RegionSpec& r);

// The voxels of `world` inside any region of `in` (all of the world when `in` is empty) and
// inside none of `out`, as a mask domain on the world's frame (terminals drawn uniformly).
// Throws GrowthError naming `what` when no voxel is left.
GrowthDomain regionDomain(const GrowthDomain& world, const std::vector<const RegionSpec*>& in, const std::vector<const RegionSpec*>& out,
                          const std::string& what);

}  // namespace angiosynth
