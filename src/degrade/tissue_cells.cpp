// Cell-like tissue texture: a Voronoi tessellation of jittered seed points (Worley 1996), each cell
// its own intensity and the walls between cells brighter or darker, as parenchyma, fat lobules
// or cells in microscopy look. Anisotropic cell sizes give fibre-like cells.
#include <algorithm>
#include <cmath>
#include <vector>

#include "degrade/effect.hpp"

namespace angiosynth {
namespace {

// One seed per lattice cell at a random position in it, and the cell's level: pure functions of
// the cell, so any thread computes the same tessellation. Tabulated over the lattice cells the grid
// can reach (its own and one ring around them).
struct SeedLattice {
  std::int64_t lo[3], n[3];
  std::vector<Vec3> seed;  // lattice units
  std::vector<float> level;
  SeedLattice(const VolumeGrid& g, const Vec3& cell, std::uint64_t key) {
    const CounterStream stream{key};
    for (int a = 0; a < 3; ++a) {
      lo[a] = -2;
      n[a] = std::int64_t(std::ceil(g.dims[a] * g.spacing_mm[a] / cell[a])) + 4;
    }
    seed.resize(std::size_t(n[0] * n[1] * n[2]));
    level.resize(seed.size());
    for (std::int64_t c = 0; c < n[2]; ++c)
      for (std::int64_t b = 0; b < n[1]; ++b)
        for (std::int64_t a = 0; a < n[0]; ++a) {
          const std::size_t i = std::size_t(a + n[0] * (b + n[1] * c));
          const std::uint64_t draw = 4 * i;
          const double u = stream.uniform(draw);
          const double v = stream.uniform(draw + 1);
          const double w = stream.uniform(draw + 2);
          seed[i] = Vec3(double(a + lo[0]) + u, double(b + lo[1]) + v, double(c + lo[2]) + w);
          double x, y;
          stream.normalPair(2 * i + 1 + 2 * seed.size(), x, y);
          level[i] = static_cast<float>(x);
        }
  }
  std::size_t index(std::int64_t a, std::int64_t b, std::int64_t c) const {
    return std::size_t((a - lo[0]) + n[0] * ((b - lo[1]) + n[1] * (c - lo[2])));
  }
};

void applyVoronoi(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const Vec3 cell = p.vec("cell_size");
  const SeedLattice lattice(s.grid, cell, ctx.rng.nextU64());
  const double amplitude = p("amplitude"), wall = p("wall"), half_wall = p("wall_thickness") / 2, mean = p("mean");
  const double h = (s.grid.spacing_mm.x + s.grid.spacing_mm.y + s.grid.spacing_mm.z) / 3;
  // Voxel centres relative to the grid's corner (voxel 0's outer face), in lattice units.
  const Vec3 corner = s.grid.origin_mm - s.grid.spacing_mm * 0.5;
  forEachVoxelIjk(s.grid, [&](std::int64_t v, std::int64_t i, std::int64_t j, std::int64_t k) {
    const Vec3 x = s.grid.centre(i, j, k) - corner;
    const Vec3 u(x.x / cell.x, x.y / cell.y, x.z / cell.z);
    const std::int64_t a0 = std::int64_t(std::floor(u.x)), b0 = std::int64_t(std::floor(u.y)), c0 = std::int64_t(std::floor(u.z));
    double d1 = INFINITY, d2 = INFINITY;
    std::size_t n1 = 0, n2 = 0;
    for (std::int64_t c = c0 - 1; c <= c0 + 1; ++c)
      for (std::int64_t b = b0 - 1; b <= b0 + 1; ++b)
        for (std::int64_t a = a0 - 1; a <= a0 + 1; ++a) {
          const std::size_t q = lattice.index(a, b, c);
          const Vec3& sq = lattice.seed[q];
          const double rx = (sq.x - u.x) * cell.x, ry = (sq.y - u.y) * cell.y, rz = (sq.z - u.z) * cell.z;  // mm
          const double d = rx * rx + ry * ry + rz * rz;
          if (d < d1) {
            d2 = d1, n2 = n1;
            d1 = d, n1 = q;
          } else if (d < d2) {
            d2 = d, n2 = q;
          }
        }
    double t = mean + amplitude * lattice.level[n1];
    if (wall != 0) {
      // Distance to the wall between the two nearest cells: the bisector plane of their seeds.
      const Vec3 &s1 = lattice.seed[n1], &s2 = lattice.seed[n2];
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
    applyVoronoi,
    /*moves_geometry=*/false,
    /*noise=*/false,
    // The seed table: 28 bytes per lattice cell, a cell at least 2 voxels on each axis.
    /*working_bytes_per_voxel=*/4};

}  // namespace angiosynth
