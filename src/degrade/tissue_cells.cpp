// Cell-like tissue texture: a Voronoi tessellation of jittered seed points (Worley 1996), each cell
// its own intensity and the walls between cells brighter or darker, as parenchyma, fat lobules
// or cells in microscopy look. Anisotropic cell sizes give fibre-like cells.
#include <cmath>

#include "degrade/effect.hpp"

namespace angiosynth {
namespace {

// One seed per lattice cell at a random position in it: a pure function of the cell, so any
// thread computes the same tessellation.
struct SeedLattice {
  CounterStream stream;
  std::uint64_t index(std::int64_t a, std::int64_t b, std::int64_t c) const {
    return mix64(std::uint64_t(a) * 0x9E3779B97F4A7C15ULL ^ std::uint64_t(b) * 0xC2B2AE3D27D4EB4FULL ^ std::uint64_t(c) * 0x165667B19E3779F9ULL);
  }
  Vec3 seed(std::int64_t a, std::int64_t b, std::int64_t c) const {
    const std::uint64_t n = index(a, b, c) * 4;
    return Vec3(a + stream.uniform(n), b + stream.uniform(n + 1), c + stream.uniform(n + 2));
  }
  double value(std::int64_t a, std::int64_t b, std::int64_t c) const {
    double x, y;
    stream.normalPair(index(a, b, c) * 2 + 1, x, y);
    return x;
  }
};

void applyVoronoi(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const SeedLattice lattice{CounterStream{ctx.rng.nextU64()}};
  const Vec3 cell = p.vec("cell_size");
  const double amplitude = p("amplitude"), wall = p("wall"), half_wall = p("wall_thickness") / 2, mean = p("mean");
  const double h = (s.grid.spacing_mm.x + s.grid.spacing_mm.y + s.grid.spacing_mm.z) / 3;
  forEachVoxelIjk(s.grid, [&](std::int64_t v, std::int64_t i, std::int64_t j, std::int64_t k) {
    const Vec3 x = s.grid.centre(i, j, k) - s.grid.origin_mm;
    const Vec3 u(x.x / cell.x, x.y / cell.y, x.z / cell.z);  // in lattice units
    const std::int64_t a0 = std::int64_t(std::floor(u.x)), b0 = std::int64_t(std::floor(u.y)), c0 = std::int64_t(std::floor(u.z));
    double d1 = INFINITY, d2 = INFINITY;
    Vec3 s1, s2;
    std::int64_t n1[3] = {0, 0, 0};
    for (std::int64_t c = c0 - 1; c <= c0 + 1; ++c)
      for (std::int64_t b = b0 - 1; b <= b0 + 1; ++b)
        for (std::int64_t a = a0 - 1; a <= a0 + 1; ++a) {
          const Vec3 q = lattice.seed(a, b, c);
          const Vec3 r((q.x - u.x) * cell.x, (q.y - u.y) * cell.y, (q.z - u.z) * cell.z);  // mm
          const double d = dot(r, r);
          if (d < d1) {
            d2 = d1, s2 = s1;
            d1 = d, s1 = q, n1[0] = a, n1[1] = b, n1[2] = c;
          } else if (d < d2) {
            d2 = d, s2 = q;
          }
        }
    double t = mean + amplitude * lattice.value(n1[0], n1[1], n1[2]);
    if (wall != 0 && std::isfinite(d2)) {
      // Distance to the wall between the two nearest cells: the bisector plane of their seeds.
      const Vec3 gap((s2.x - s1.x) * cell.x, (s2.y - s1.y) * cell.y, (s2.z - s1.z) * cell.z);
      const double to_wall = (d2 - d1) / (2 * std::max(norm(gap), 1e-12));
      t += wall * std::clamp(0.5 - (to_wall - half_wall) / h, 0.0, 1.0);
    }
    s.image.data[v] += static_cast<float>((1.0 - s.fraction->data[v]) * t);
  });
}

}  // namespace

extern const EffectType kVoronoi{
    "voronoi",
    "cell-like tissue texture: a Voronoi tessellation of jittered seeds, each cell mean + amplitude × N(0, 1) and the walls between "
    "cells wall brighter, added where the vessels leave room",
    {{"cell_size", ParamKind::Length3, 1e-9, 1e9, "0.1 fov", "spacing of the seed lattice (the typical cell diameter); per axis for elongated cells",
      1},
     {"amplitude", ParamKind::Intensity, 0, 1e9, nullptr, "standard deviation of the cells' intensities"},
     {"mean", ParamKind::Intensity, -1e9, 1e9, "0", "added to the background before the cells"},
     {"wall", ParamKind::Intensity, -1e9, 1e9, "0", "intensity the walls between cells add (negative: darker walls)"},
     {"wall_thickness", ParamKind::Length, 0, 1e9, "1 voxel", "thickness of the walls"}},
    applyVoronoi};

}  // namespace angiosynth
