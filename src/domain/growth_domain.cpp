#include "domain/growth_domain.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/distributions.hpp"

namespace angiosynth {

const char* domainShapeName(DomainShape s) {
  switch (s) {
    case DomainShape::Sphere: return "sphere";
    case DomainShape::Cube: return "cube";
    case DomainShape::Disc: return "disc";
    case DomainShape::Square: return "square";
    case DomainShape::Mask: return "mask";
  }
  return "?";
}

namespace {

bool isRound(DomainShape s) { return s == DomainShape::Sphere || s == DomainShape::Disc; }
bool isFlat(DomainShape s) { return s == DomainShape::Disc || s == DomainShape::Square; }

}  // namespace

std::array<std::int32_t, 3> GrowthDomain::analyticDims(DomainShape shape, double size_mm, double voxel_mm, int margin_voxels) {
  const double half = isRound(shape) ? size_mm : size_mm / 2;
  const int n = 2 * (static_cast<int>(std::ceil(half / voxel_mm - 1e-9)) + margin_voxels);
  return {n, n, isFlat(shape) ? 1 : n};
}

GrowthDomain GrowthDomain::analytic(DomainShape shape, double size_mm, double voxel_mm, int margin_voxels) {
  GrowthDomain d;
  d.shape_ = shape;
  const bool round = isRound(shape);
  d.dimension_ = isFlat(shape) ? 2 : 3;
  d.size_ = round ? size_mm : size_mm / 2;
  const double h = d.size_;
  auto& m = d.map_;
  m.voxel_mm = voxel_mm;
  m.dims = analyticDims(shape, size_mm, voxel_mm, margin_voxels);
  d.center_ = Vec3(m.dims[0], m.dims[1], m.dims[2]) * (voxel_mm / 2);
  if (d.dimension_ == 2)
    d.measure_ = round ? std::numbers::pi * h * h : 4 * h * h;
  else
    d.measure_ = round ? 4.0 / 3.0 * std::numbers::pi * h * h * h : 8 * h * h * h;
  m.demand.assign(m.voxelCount(), 0.0f);
  for (int k = 0; k < m.dims[2]; ++k)
    for (int j = 0; j < m.dims[1]; ++j)
      for (int i = 0; i < m.dims[0]; ++i)
        if (d.depth(Vec3(i + 0.5, j + 0.5, k + 0.5) * voxel_mm) > 0) m.demand[m.flat(i, j, k)] = 1.0f;
  m.supply_index.assign(m.voxelCount(), 0);
  m.supply_sets = {{}};
  return d;
}

GrowthDomain GrowthDomain::mask(DemandMap map, bool demand_weighted) {
  GrowthDomain d;
  d.shape_ = DomainShape::Mask;
  d.dimension_ = map.dims[2] == 1 ? 2 : 3;
  d.demand_weighted_ = demand_weighted;
  d.map_ = std::move(map);
  auto& m = d.map_;
  std::int64_t inside = 0;
  std::vector<float> weights(m.demand.size(), 0.0f);
  for (std::size_t v = 0; v < m.demand.size(); ++v)
    if (m.demand[v] > 0) {
      ++inside;
      weights[v] = demand_weighted ? m.demand[v] : 1.0f;
    }
  double total = 0;
  for (float w : weights) total += w;
  d.mean_weight_ = inside ? total / double(inside) : 1.0;
  const double h = m.voxel_mm;
  d.measure_ = double(inside) * (d.dimension_ == 2 ? h * h : h * h * h);
  d.center_ = m.extentMm() * 0.5;
  d.size_ = 0;
  d.depth_ = maskDepthMap(m);
  if (demand_weighted) {
    d.sampler_ = std::make_shared<DemandSampler>(weights);
  } else {  // equal weights: the k-th inside voxel, k = ⌊u·N⌋, as the sum tree would pick it, in O(N) memory
    auto in = std::make_shared<std::vector<std::int64_t>>();
    in->reserve(std::size_t(inside));
    for (std::size_t v = 0; v < weights.size(); ++v)
      if (weights[v] > 0) in->push_back(std::int64_t(v));
    d.inside_ = std::move(in);
  }
  return d;
}

double GrowthDomain::maskDepth(const Vec3& p) const {
  // Trilinear interpolation of the voxel-centre depths; outside the map is outside.
  const auto& m = map_;
  const Vec3 u = p / m.voxel_mm - Vec3(0.5, 0.5, 0.5);
  const double lim[3] = {double(m.dims[0]), double(m.dims[1]), double(m.dims[2])};
  const double c[3] = {u.x, u.y, dimension_ == 2 ? 0.0 : u.z};
  for (int a = 0; a < 3; ++a)
    if (c[a] < -0.5 || c[a] > lim[a] - 0.5) return -m.voxel_mm;
  int i0[3];
  double f[3];
  for (int a = 0; a < 3; ++a) {
    const double cl = std::clamp(c[a], 0.0, lim[a] - 1);
    i0[a] = std::min(static_cast<int>(std::floor(cl)), std::max(0, static_cast<int>(lim[a]) - 2));
    f[a] = lim[a] > 1 ? cl - i0[a] : 0;
  }
  double v = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const int di = corner & 1, dj = (corner >> 1) & 1, dk = (corner >> 2) & 1;
    const int i = std::min(i0[0] + di, m.dims[0] - 1), j = std::min(i0[1] + dj, m.dims[1] - 1), k = std::min(i0[2] + dk, m.dims[2] - 1);
    const double w = (di ? f[0] : 1 - f[0]) * (dj ? f[1] : 1 - f[1]) * (dk ? f[2] : 1 - f[2]);
    if (w != 0) v += w * depth_[m.flat(i, j, k)];
  }
  // Interpolation overestimates the depth near a concave edge of the mask (the distance there is
  // a cone): a point in a voxel outside the mask is never inside.
  const int vi = std::min(static_cast<int>(std::floor(c[0] + 0.5)), m.dims[0] - 1),
            vj = std::min(static_cast<int>(std::floor(c[1] + 0.5)), m.dims[1] - 1),
            vk = dimension_ == 2 ? 0 : std::min(static_cast<int>(std::floor(c[2] + 0.5)), m.dims[2] - 1);
  return depth_[m.flat(vi, vj, vk)] < 0 ? std::min(v, 0.0) : v;
}

double GrowthDomain::depth(const Vec3& p) const {
  const Vec3 d = p - center_;
  switch (shape_) {
    case DomainShape::Sphere: return size_ - norm(d);
    case DomainShape::Disc: return size_ - std::sqrt(d.x * d.x + d.y * d.y);
    case DomainShape::Cube: return size_ - std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
    case DomainShape::Square: return size_ - std::max(std::abs(d.x), std::abs(d.y));
    case DomainShape::Mask: return maskDepth(p);
  }
  return -1;
}

bool GrowthDomain::capsuleInside(const Vec3& a, const Vec3& b, double r, bool starts_at_root) const {
  const bool convex = shape_ != DomainShape::Mask;
  if (convex && !starts_at_root) return depth(a) >= r && depth(b) >= r;  // depth is concave
  const double len = distance(a, b);
  // Steps of a quarter voxel (the depth map's resolution) and at most r/2 near the root.
  double step = map_.voxel_mm / 4;
  if (starts_at_root) step = std::min(step, std::max(r / 2, 1e-6 * len));
  const int n = std::max(1, static_cast<int>(std::ceil(len / step)));
  for (int i = 0; i <= n; ++i) {
    const double t = double(i) / n;
    const Vec3 p = a + (b - a) * t;
    const double need = starts_at_root ? std::min(r, t * len - r) : r;
    if (depth(p) < need) return false;
  }
  return true;
}

Vec3 GrowthDomain::sample(Rng& rng) const {
  if (shape_ != DomainShape::Mask) {
    // Rejection from the bounding box: exactly uniform.
    for (;;) {
      const Vec3 u = uniformPoint(rng, -1, 1, dimension_ == 2);
      const Vec3 p = center_ + u * size_;
      if (depth(p) > 0) return p;
    }
  }
  const auto& m = map_;
  for (;;) {
    const double u = rng.uniform();
    std::int64_t v = -1;
    if (sampler_) {
      v = sampler_->sample(u);
    } else {
      const double rank = u * double(inside_->size());  // u·N may round up to N: no voxel, draw again
      if (rank < double(inside_->size())) v = (*inside_)[std::size_t(rank)];
    }
    const Vec3 jitter = uniformPoint(rng, 0, 1, dimension_ == 2, 0.5);
    if (v < 0) continue;
    const std::int64_t nx = m.dims[0], ny = m.dims[1];
    const Vec3 p = m.toMm(Vec3(double(v % nx), double((v / nx) % ny), double(v / (nx * ny))) + jitter);
    if (depth(p) > 0) return p;
  }
}

double GrowthDomain::spacingScale(const Vec3& p) const {
  if (!demand_weighted_) return 1.0;
  const auto v = map_.voxelAt(p);
  const double w = v >= 0 ? map_.demand[v] : 0.0;
  return w > 0 ? std::pow(mean_weight_ / w, 1.0 / dimension_) : 1.0;
}

Vec3 GrowthDomain::defaultRoot() const {
  if (shape_ == DomainShape::Mask) throw std::logic_error("a mask domain has no default root");
  return center_ + Vec3(0, size_, 0);
}

}  // namespace angiosynth
