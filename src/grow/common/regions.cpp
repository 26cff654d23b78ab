#include "grow/common/regions.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "grow/common/growth_report.hpp"

namespace angiosynth {

const char* regionShapeName(RegionShape s) {
  switch (s) {
    case RegionShape::Sphere: return "sphere";
    case RegionShape::Disc: return "disc";
    case RegionShape::Shell: return "shell";
    case RegionShape::Annulus: return "annulus";
    case RegionShape::Box: return "box";
  }
  return "";
}

double regionDepth(const RegionSpec& r, const Vec3& p, const Vec3& domain_centre) {
  Vec3 d = p - (domain_centre + r.centre);
  const bool flat = r.shape == RegionShape::Disc || r.shape == RegionShape::Annulus;
  if (flat) d.z = 0;
  switch (r.shape) {
    case RegionShape::Sphere:
    case RegionShape::Disc: return r.radius - norm(d);
    case RegionShape::Shell:
    case RegionShape::Annulus: return std::min(norm(d) - r.inner, r.outer - norm(d));
    case RegionShape::Box: {
      // Exact signed distance of a box: inside, to the nearest face; outside, to the box.
      // A 2D box (no z side) ignores z like the disc.
      const Vec3 q(std::abs(d.x) - r.size.x / 2, std::abs(d.y) - r.size.y / 2, r.size.z > 0 ? std::abs(d.z) - r.size.z / 2 : -1e300);
      const Vec3 out(std::max(q.x, 0.0), std::max(q.y, 0.0), std::max(q.z, 0.0));
      return -(norm(out) + std::min(std::max({q.x, q.y, q.z}), 0.0));
    }
  }
  return -1;
}

double regionMeasure(const RegionSpec& r) {
  const double pi = std::numbers::pi;
  switch (r.shape) {
    case RegionShape::Sphere: return 4.0 / 3.0 * pi * r.radius * r.radius * r.radius;
    case RegionShape::Disc: return pi * r.radius * r.radius;
    case RegionShape::Shell: return 4.0 / 3.0 * pi * (std::pow(r.outer, 3) - std::pow(r.inner, 3));
    case RegionShape::Annulus: return pi * (r.outer * r.outer - r.inner * r.inner);
    case RegionShape::Box: return r.size.x * r.size.y * (r.size.z > 0 ? r.size.z : 1.0);
  }
  return 0;
}

GrowthDomain regionDomain(const GrowthDomain& world, const std::vector<const RegionSpec*>& in, const std::vector<const RegionSpec*>& out,
                          const std::string& what) {
  DemandMap m = world.frame();
  const Vec3 c = world.center();
  std::int64_t kept = 0;
  for (int k = 0; k < m.dims[2]; ++k)
    for (int j = 0; j < m.dims[1]; ++j)
      for (int i = 0; i < m.dims[0]; ++i) {
        const auto v = m.flat(i, j, k);
        if (!(m.demand[v] > 0)) continue;
        const Vec3 p = m.toMm(Vec3(i + 0.5, j + 0.5, k + 0.5));
        const bool inside = in.empty() || std::any_of(in.begin(), in.end(), [&](auto* r) { return regionDepth(*r, p, c) > 0; });
        const bool excluded = std::any_of(out.begin(), out.end(), [&](auto* r) { return regionDepth(*r, p, c) > 0; });
        m.demand[v] = inside && !excluded ? 1.0f : 0.0f;
        kept += inside && !excluded;
      }
  if (kept == 0) throw GrowthError(what + " holds no voxel of the domain's frame; check its regions' centres and sizes");
  return GrowthDomain::mask(std::move(m), false);
}

std::vector<const RegionSpec*> regionsNamed(const std::vector<RegionSpec>& all, const std::vector<std::string>& names) {
  std::vector<const RegionSpec*> out;
  for (const auto& n : names)
    for (const auto& r : all)
      if (r.name == n) out.push_back(&r);
  return out;
}

}  // namespace angiosynth
