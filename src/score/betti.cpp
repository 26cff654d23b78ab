#include "score/betti.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <functional>
#include <numeric>
#include <vector>

namespace angiosynth {
namespace {

struct UnionFind {
  std::vector<std::int32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::int32_t find(std::int32_t x) {
    while (parent[std::size_t(x)] != x) x = parent[std::size_t(x)] = parent[std::size_t(parent[std::size_t(x)])];
    return x;
  }
  void unite(std::int32_t a, std::int32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::size_t(std::max(a, b))] = std::min(a, b);
  }
};

}  // namespace

std::int64_t countComponents(const Volume<std::uint8_t>& v, std::uint8_t value, int connectivity, bool padded) {
  const int pad = padded ? 1 : 0;
  const std::int64_t nx = v.grid.dims[0] + 2 * pad, ny = v.grid.dims[1] + 2 * pad, nz = v.grid.dims[2] + 2 * pad;
  const auto in = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    const std::int64_t a = i - pad, b = j - pad, c = k - pad;
    const bool inside = a >= 0 && b >= 0 && c >= 0 && a < v.grid.dims[0] && b < v.grid.dims[1] && c < v.grid.dims[2];
    return (inside ? v.at(a, b, c) != 0 : false) == (value != 0);
  };
  const auto id = [&](std::int64_t i, std::int64_t j, std::int64_t k) { return std::int32_t((k * ny + j) * nx + i); };
  // Earlier neighbours in scan order: 3 face neighbours, or all 13 of the 26.
  std::vector<std::array<int, 3>> back;
  for (int dz = -1; dz <= 0; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;
        if (connectivity == 6 && std::abs(dx) + std::abs(dy) + std::abs(dz) != 1) continue;
        back.push_back({dx, dy, dz});
      }
  UnionFind uf(std::size_t(nx * ny * nz));
  std::int64_t count = 0;
  for (std::int64_t k = 0; k < nz; ++k)
    for (std::int64_t j = 0; j < ny; ++j)
      for (std::int64_t i = 0; i < nx; ++i) {
        if (!in(i, j, k)) continue;
        ++count;
        for (const auto& d : back) {
          const std::int64_t a = i + d[0], b = j + d[1], c = k + d[2];
          if (a < 0 || b < 0 || c < 0 || a >= nx || b >= ny || !in(a, b, c)) continue;
          const auto x = uf.find(id(i, j, k)), y = uf.find(id(a, b, c));
          if (x != y) uf.unite(x, y), --count;
        }
      }
  return count;
}

Betti bettiNumbers(const Volume<std::uint8_t>& v) {
  const auto& g = v.grid;
  const std::int64_t nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  const auto fg = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    return i >= 0 && j >= 0 && k >= 0 && i < nx && j < ny && k < nz && v.at(i, j, k) != 0;
  };
  // χ of the union of closed cubes: V − E + F − C over the lattice, each cell present when a
  // voxel it bounds is foreground (integer sums per slice: the same for any threads).
  const std::int64_t chi = tbb::parallel_reduce(
      tbb::blocked_range<std::int64_t>(0, nz + 1), std::int64_t(0),
      [&](const tbb::blocked_range<std::int64_t>& r, std::int64_t acc) {
        for (std::int64_t k = r.begin(); k < r.end(); ++k)
          for (std::int64_t j = 0; j <= ny; ++j)
            for (std::int64_t i = 0; i <= nx; ++i) {
              // The 8 voxels around lattice point (i, j, k): bit (dx, dy, dz) for voxel (i−1+dx, …).
              int m = 0;
              for (int b = 0; b < 8; ++b) m |= int(fg(i - 1 + (b & 1), j - 1 + ((b >> 1) & 1), k - 1 + ((b >> 2) & 1))) << b;
              if (!m) continue;
              ++acc;  // the vertex
              // Edges from this point in +x, +y, +z, each bounded by 4 voxels of the cell; faces in
              // the +x+y, +x+z, +y+z quadrants (2 voxels); the cube (i, j, k) (1 voxel).
              const bool x_edge = fg(i, j - 1, k - 1) || fg(i, j, k - 1) || fg(i, j - 1, k) || fg(i, j, k);
              const bool y_edge = fg(i - 1, j, k - 1) || fg(i, j, k - 1) || fg(i - 1, j, k) || fg(i, j, k);
              const bool z_edge = fg(i - 1, j - 1, k) || fg(i, j - 1, k) || fg(i - 1, j, k) || fg(i, j, k);
              const bool xy_face = fg(i, j, k - 1) || fg(i, j, k);
              const bool xz_face = fg(i, j - 1, k) || fg(i, j, k);
              const bool yz_face = fg(i - 1, j, k) || fg(i, j, k);
              acc -= std::int64_t(x_edge) + y_edge + z_edge;
              acc += std::int64_t(xy_face) + xz_face + yz_face;
              acc -= fg(i, j, k);
            }
        return acc;
      },
      std::plus<std::int64_t>());
  Betti b;
  b.euler = chi;
  b.b0 = countComponents(v, 1, 26, false);
  b.b2 = countComponents(v, 0, 6, true) - 1;  // the outside is one background piece
  b.b1 = b.b0 + b.b2 - chi;
  return b;
}

}  // namespace angiosynth
