#include "degrade/warp.hpp"

#include <cmath>

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "degrade/effect.hpp"

namespace angiosynth {
namespace {

std::array<BSplineField, 3> makeFields(const VolumeGrid& g, const Vec3& spacing, const Vec3& max_disp, Rng& rng) {
  std::array<BSplineField, 3> u{BSplineField(g, spacing), BSplineField(g, spacing), BSplineField(g, spacing)};
  for (int c = 0; c < 3; ++c) {
    for (auto& k : u[c].coefficients()) k = static_cast<float>(max_disp[c] * (2 * rng.uniform() - 1));
    u[c].prepare();
  }
  return u;
}

double det3(const std::array<double, 9>& m) {
  return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) + m[2] * (m[3] * m[7] - m[4] * m[6]);
}

// Solves m·x = b (Cramer's rule; m is near the identity here).
Vec3 solve3(const std::array<double, 9>& m, const Vec3& b) {
  const double d = det3(m);
  const auto col = [&](int c) {
    std::array<double, 9> k = m;
    for (int r = 0; r < 3; ++r) k[3 * r + c] = b[r];
    return det3(k) / d;
  };
  return Vec3(col(0), col(1), col(2));
}

std::array<double, 9> identityPlus(const std::array<double, 9>& j) {
  std::array<double, 9> m = j;
  m[0] += 1, m[4] += 1, m[8] += 1;
  return m;
}

}  // namespace

BSplineWarp::BSplineWarp(const VolumeGrid& grid, const Vec3& spacing, const Vec3& max_disp, Rng& rng)
    : grid_(grid), u_(makeFields(grid, spacing, max_disp, rng)) {}

Vec3 BSplineWarp::displacement(const Vec3& y, std::array<double, 9>* jac) const {
  Vec3 out, grad[3];
  double v[3];
  for (int c = 0; c < 3; ++c) v[c] = u_[c].at(y, jac ? &grad[c] : nullptr);
  out = Vec3(v[0], v[1], v[2]);
  if (jac)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) (*jac)[3 * r + c] = grad[r][c];
  return out;
}

Vec3 BSplineWarp::forward(const Vec3& x) const {
  Vec3 y = x - displacement(x);
  for (int it = 0; it < 30; ++it) {
    std::array<double, 9> j;
    const Vec3 f = y + displacement(y, &j) - x;
    if (dot(f, f) < 1e-24) break;
    y = y - solve3(identityPlus(j), f);
  }
  return y;
}

double BSplineWarp::minJacobianDeterminant(int stride) const {
  // A minimum is order-independent, so the parallel reduction is deterministic.
  const std::int64_t nx = (grid_.dims[0] + stride - 1) / stride, ny = (grid_.dims[1] + stride - 1) / stride;
  const std::int64_t nz = (grid_.dims[2] + stride - 1) / stride;
  return tbb::parallel_reduce(
      tbb::blocked_range<std::int64_t>(0, nx * ny * nz), INFINITY,
      [&](const tbb::blocked_range<std::int64_t>& r, double lo) {
        for (std::int64_t q = r.begin(); q < r.end(); ++q) {
          std::array<double, 9> jac;
          displacement(grid_.centre(q % nx * stride, (q / nx) % ny * stride, q / (nx * ny) * stride), &jac);
          lo = std::min(lo, det3(identityPlus(jac)));
        }
        return lo;
      },
      [](double a, double b) { return std::min(a, b); });
}

nlohmann::ordered_json BSplineWarp::describe() const {
  const auto& f = u_[0];
  const Vec3 o = f.latticeOrigin(), h = f.spacing();
  nlohmann::ordered_json j;
  j["definition"] =
      "warped image at y = clean image at y + u(y); u is a uniform cubic B-spline with control point (a,b,c) at "
      "origin + (a,b,c)*spacing; displacements are listed x fastest; clean points x move to the y solving y + u(y) = x";
  j["lattice"] = {f.lattice()[0], f.lattice()[1], f.lattice()[2]};
  j["origin_mm"] = {o.x, o.y, o.z};
  j["spacing_mm"] = {h.x, h.y, h.z};
  for (int c = 0; c < 3; ++c) j[std::string("displacement_") + "xyz"[c] + "_mm"] = u_[c].coefficients();
  return j;
}

VascularTree warpTree(const VascularTree& t, const BSplineWarp& warp, double piece_mm, std::vector<std::int32_t>& origin) {
  VascularTree w;
  origin.clear();
  if (t.nodeCount() == 0) return w;
  std::vector<std::int32_t> node_of(t.nodeCount(), -1);
  // Points first (in parallel; each is an independent Newton solve), then links in tree order.
  std::vector<std::int32_t> order = t.topDownOrder();
  std::vector<std::int64_t> first_point(t.nodeCount() + 1, 0);
  std::vector<int> pieces(t.nodeCount(), 0);
  for (std::int32_t n = 0; n < t.nodeCount(); ++n) pieces[n] = t.isRoot(n) ? 1 : std::max(1, static_cast<int>(std::ceil(t.length[n] / piece_mm)));
  for (std::int32_t n = 0; n < t.nodeCount(); ++n) first_point[n + 1] = first_point[n] + pieces[n];
  std::vector<Vec3> moved(first_point.back());
  std::vector<double> scale(first_point.back(), 1.0);
  tbb::parallel_for(std::int32_t(0), t.nodeCount(), [&](std::int32_t n) {
    if (t.isRoot(n)) {
      moved[first_point[n]] = warp.forward(t.position[n]);
      return;
    }
    const Vec3 a = t.position[t.parent[n]], b = t.position[n];
    const Vec3 dir = (b - a) / std::max(t.length[n], 1e-300);
    for (int q = 1; q <= pieces[n]; ++q) {
      const std::int64_t at = first_point[n] + q - 1;
      moved[at] = warp.forward(a + (b - a) * (double(q) / pieces[n]));
      // Cross-section stretch at the piece's middle: area scales by det(J)/|J·d| with J = ∂φ/∂x.
      const Vec3 mid = warp.forward(a + (b - a) * ((q - 0.5) / pieces[n]));
      std::array<double, 9> ju;
      warp.displacement(mid, &ju);
      const std::array<double, 9> jpsi = identityPlus(ju);  // ∂ψ/∂y = (∂φ/∂x)⁻¹
      const Vec3 jd = solve3(jpsi, dir);                    // J·d
      scale[at] = std::sqrt(1.0 / (det3(jpsi) * norm(jd)));
    }
  });
  w.reserve(moved.size());
  for (std::int32_t n : order) {
    if (t.isRoot(n)) {  // a root starts its tree (its segment id is its own)
      node_of[n] = w.addNode(moved[first_point[n]], -1, t.tree[n]);
      w.pressure[node_of[n]] = t.pressure[n];
      origin.push_back(n);
      continue;
    }
    std::int32_t prev = node_of[t.parent[n]];
    for (int q = 1; q <= pieces[n]; ++q) {
      const std::int64_t at = first_point[n] + q - 1;
      const std::int32_t id = w.addNode(moved[at], prev);
      const double f = double(q) / pieces[n];
      w.setPieceOf(t, n, q, pieces[n], id);
      // The cross-section stretches with the warp.
      w.radius[id] *= scale[at];
      if (t.radius_start[n] >= 0) w.radius_start[id] *= scale[at];
      w.wall_start[id] *= scale[at];
      w.wall[id] *= scale[at];
      w.pressure[id] = t.pressure[t.parent[n]] + f * (t.pressure[n] - t.pressure[t.parent[n]]);  // linear along a Poiseuille tube
      w.beta[id] = t.beta[n];
      origin.push_back(n);
      prev = id;
    }
    node_of[n] = prev;
  }
  return w;
}

float sampleTrilinear(const Volume<float>& v, const Vec3& p) {
  const auto& d = v.grid.dims;
  std::int64_t i0[3];
  float f[3];
  for (int ax = 0; ax < 3; ++ax) {
    const double x = std::clamp(p[ax], 0.0, double(d[ax] - 1));
    i0[ax] = std::min<std::int64_t>(static_cast<std::int64_t>(x), std::max(0, d[ax] - 2));
    f[ax] = d[ax] > 1 ? static_cast<float>(x - i0[ax]) : 0.0f;
  }
  const std::int64_t sx = d[0] > 1 ? 1 : 0, sy = d[1] > 1 ? d[0] : 0, sz = d[2] > 1 ? std::int64_t(d[0]) * d[1] : 0;
  const float* b = v.data.data() + v.grid.flat(i0[0], i0[1], i0[2]);
  const float c00 = b[0] + f[0] * (b[sx] - b[0]), c10 = b[sy] + f[0] * (b[sy + sx] - b[sy]);
  const float c01 = b[sz] + f[0] * (b[sz + sx] - b[sz]), c11 = b[sz + sy] + f[0] * (b[sz + sy + sx] - b[sz + sy]);
  const float c0 = c00 + f[1] * (c10 - c00), c1 = c01 + f[1] * (c11 - c01);
  return c0 + f[2] * (c1 - c0);
}

Volume<float> warpVolume(const Volume<float>& v, const BSplineWarp& warp) {
  const VolumeGrid& g = v.grid;
  Volume<float> out(g);
  forEachVoxelIjk(g, [&](std::int64_t q, std::int64_t i, std::int64_t j, std::int64_t k) {
    const Vec3 u = warp.displacementAtVoxel(i, j, k);
    out.data[q] = sampleTrilinear(v, Vec3(i + u.x / g.spacing_mm.x, j + u.y / g.spacing_mm.y, k + u.z / g.spacing_mm.z));
  });
  return out;
}

Volume<std::uint8_t> warpLabelNearest(const Volume<std::uint8_t>& v, const BSplineWarp& warp) {
  const VolumeGrid& g = v.grid;
  Volume<std::uint8_t> out(g);
  forEachVoxelIjk(g, [&](std::int64_t q, std::int64_t i, std::int64_t j, std::int64_t k) {
    const Vec3 u = warp.displacementAtVoxel(i, j, k);
    const std::int64_t p[3] = {std::llround(i + u.x / g.spacing_mm.x), std::llround(j + u.y / g.spacing_mm.y),
                               std::llround(k + u.z / g.spacing_mm.z)};
    if (p[0] < 0 || p[1] < 0 || p[2] < 0 || p[0] >= g.dims[0] || p[1] >= g.dims[1] || p[2] >= g.dims[2]) return;
    out.data[q] = v.at(p[0], p[1], p[2]);
  });
  return out;
}

GroundTruthVolumes warpedLabels(const Volume<float>& wf, const VascularTree& wt, const std::vector<std::int32_t>& origin,
                                const Volume<std::uint32_t>& clean, const BSplineWarp& warp, int centerline_connectivity) {
  const VolumeGrid& g = wf.grid;
  GroundTruthVolumes gt;
  gt.fraction = wf;
  gt.mask = Volume<std::uint8_t>(g);
  gt.centerline = Volume<std::uint8_t>(g);
  gt.radius = Volume<float>(g);
  gt.instances = Volume<std::uint32_t>(g);
  gt.centerline_connectivity = centerline_connectivity;
  forEachVoxelIjk(g, [&](std::int64_t q, std::int64_t i, std::int64_t j, std::int64_t k) {
    if (wf.data[q] < 0.5f) return;
    gt.mask.data[q] = 1;
    const Vec3 u = warp.displacementAtVoxel(i, j, k);
    const Vec3 p(i + u.x / g.spacing_mm.x, j + u.y / g.spacing_mm.y, k + u.z / g.spacing_mm.z);
    // The labelled corner of the trilinear stencil with the largest weight.
    std::int64_t c0[3];
    double f[3];
    for (int ax = 0; ax < 3; ++ax) {
      const double x = std::clamp(p[ax], 0.0, double(g.dims[ax] - 1));
      c0[ax] = std::min<std::int64_t>(static_cast<std::int64_t>(x), std::max(0, g.dims[ax] - 2));
      f[ax] = x - c0[ax];
    }
    double best = -1;
    std::uint32_t label = 0;
    for (int c = 0; c < 8; ++c) {
      const std::int64_t ci = std::min<std::int64_t>(c0[0] + (c & 1), g.dims[0] - 1);
      const std::int64_t cj = std::min<std::int64_t>(c0[1] + ((c >> 1) & 1), g.dims[1] - 1);
      const std::int64_t ck = std::min<std::int64_t>(c0[2] + ((c >> 2) & 1), g.dims[2] - 1);
      const std::uint32_t l = clean.at(ci, cj, ck);
      const double w = (c & 1 ? f[0] : 1 - f[0]) * ((c >> 1) & 1 ? f[1] : 1 - f[1]) * ((c >> 2) & 1 ? f[2] : 1 - f[2]);
      if (l != 0 && w > best) best = w, label = l;
    }
    gt.instances.data[q] = label;
  });
  addCenterlines(wt, gt, &origin);
  return gt;
}

namespace {

void applyWarp(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const Vec3 h = p.vec("spacing"), m = p.vec("max_displacement");
  for (int ax = 0; ax < 3; ++ax)
    if (m[ax] > BSplineWarp::kMaxDisplacementPerSpacing * h[ax] + 1e-12)
      throw std::invalid_argument("warp: max_displacement " + std::to_string(m[ax]) + " mm exceeds 0.4 × spacing (" +
                                  std::to_string(BSplineWarp::kMaxDisplacementPerSpacing * h[ax]) + " mm) on axis " + std::to_string(ax) +
                                  ", beyond which the warp may fold; allowed: <= 0.4 × spacing");
  auto warp = std::make_shared<BSplineWarp>(s.grid, h, m, ctx.rng);
  s.image = warpVolume(s.image, *warp);
  s.warped_fraction = std::make_shared<Volume<float>>(warpVolume(*s.fraction, *warp));
  if (!s.distractors.data.empty()) s.distractors = warpLabelNearest(s.distractors, *warp);
  const double min_spacing = std::min({s.grid.spacing_mm.x, s.grid.spacing_mm.y, s.grid.spacing_mm.z});
  // Pieces shorter than 1/16 voxel add points, not accuracy: that is the floor.
  const double piece = std::max(min_spacing / 16, std::min({p("piece_length") > 0 ? p("piece_length") : min_spacing, h.x / 8, h.y / 8, h.z / 8}));
  s.warped_tree = std::make_shared<VascularTree>(warpTree(*s.tree, *warp, piece, s.segment_origin));
  s.fraction = s.warped_fraction.get();
  s.tree = s.warped_tree.get();
  s.warp = warp;
  ctx.record["piece_length_mm"] = piece;
  // Sampled on about 32³ points (at least every 4th voxel).
  const int stride = std::max(4, (std::max({s.grid.dims[0], s.grid.dims[1], s.grid.dims[2]}) + 31) / 32);
  ctx.record["min_jacobian_determinant"] = warp->minJacobianDeterminant(stride);
  ctx.record["warped_segments"] = s.warped_tree->segmentCount();
}

}  // namespace

extern const EffectType kWarp{
    "warp",
    "random cubic B-spline deformation of the image, the labels and the tree (curved vessels), invertible by construction",
    {{"spacing", ParamKind::Length3, 1e-9, 1e9, "0.25 fov", "control-point spacing; at least 1 voxel", 1},
     {"max_displacement", ParamKind::Length3, 0, 1e9, "0.05 fov", "largest control displacement per axis (<= 0.4 × spacing)"},
     {"piece_length", ParamKind::Length, 0, 1e9, "0",
      "longest piece of a warped vessel in the warped graph (0: one voxel); "
      "never more than spacing / 8, never less than 1/16 voxel"}},
    applyWarp,
    /*moves_geometry=*/true};

}  // namespace angiosynth
