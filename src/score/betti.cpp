#include "score/betti.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <functional>
#include <numeric>
#include <vector>

#include "core/union_find.hpp"

namespace angiosynth {

std::int64_t countComponents(const Volume<std::uint8_t>& v, std::uint8_t value, int connectivity, bool padded) {
  // Runs of equal voxels along x, one union-find node per run: the work scales with the runs, not
  // the voxels (a vessel volume is mostly long runs of background).
  const int pad = padded ? 1 : 0;
  const std::int64_t nx = v.grid.dims[0] + 2 * pad, ny = v.grid.dims[1] + 2 * pad, nz = v.grid.dims[2] + 2 * pad;
  const bool want = value != 0;
  const auto in = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    const std::int64_t a = i - pad, b = j - pad, c = k - pad;
    const bool inside = a >= 0 && b >= 0 && c >= 0 && a < v.grid.dims[0] && b < v.grid.dims[1] && c < v.grid.dims[2];
    return (inside && v.at(a, b, c) != 0) == want;
  };
  struct Run {
    std::int64_t x0, x1;  // [x0, x1]
    std::int32_t id;
  };
  std::vector<std::vector<Run>> lines(std::size_t(ny * nz));
  std::int32_t runs = 0;
  for (std::int64_t k = 0; k < nz; ++k)
    for (std::int64_t j = 0; j < ny; ++j) {
      auto& line = lines[std::size_t(k * ny + j)];
      for (std::int64_t i = 0; i < nx;) {
        if (!in(i, j, k)) {
          ++i;
          continue;
        }
        const std::int64_t start = i;
        while (i < nx && in(i, j, k)) ++i;
        line.push_back({start, i - 1, runs++});
      }
    }
  UnionFind uf{std::size_t(runs)};
  std::int64_t count = runs;
  // Earlier lines that touch line (j, k): (j−1, k) and (j, k−1) face to face; with 26-connectivity
  // also the diagonal lines, and runs whose x ranges come within one voxel.
  const int reach = connectivity == 26 ? 1 : 0;
  for (std::int64_t k = 0; k < nz; ++k)
    for (std::int64_t j = 0; j < ny; ++j)
      for (int dz = -1; dz <= 0; ++dz)
        for (int dy = -1; dy <= 1; ++dy) {
          if (dz == 0 && dy >= 0) continue;
          if (connectivity == 6 && dy != 0 && dz != 0) continue;
          if (connectivity == 6 && dz == -1 && dy != 0) continue;
          const std::int64_t jj = j + dy, kk = k + dz;
          if (jj < 0 || kk < 0 || jj >= ny) continue;
          const auto& a = lines[std::size_t(k * ny + j)];
          const auto& b = lines[std::size_t(kk * ny + jj)];
          std::size_t q = 0;
          for (const Run& r : a) {
            while (q < b.size() && b[q].x1 + reach < r.x0) ++q;
            for (std::size_t w = q; w < b.size() && b[w].x0 - reach <= r.x1; ++w) {
              const auto x = uf.find(r.id), y = uf.find(b[w].id);
              if (x != y) uf.unite(x, y), --count;
            }
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
  // voxel it bounds is foreground. Only the corners of foreground voxels have any: each vertex is
  // counted once, by the first (lowest x, y, z in scan order) foreground voxel around it.
  // Integer sums per slice: the same for any threads.
  const std::int64_t chi = tbb::parallel_reduce(
      tbb::blocked_range<std::int64_t>(0, nz), std::int64_t(0),
      [&](const tbb::blocked_range<std::int64_t>& r, std::int64_t acc) {
        for (std::int64_t vk = r.begin(); vk < r.end(); ++vk)
          for (std::int64_t vj = 0; vj < ny; ++vj)
            for (std::int64_t vi = 0; vi < nx; ++vi) {
              if (!v.at(vi, vj, vk)) continue;
              for (int corner = 0; corner < 8; ++corner) {
                // Lattice point (i, j, k) at this corner of voxel (vi, vj, vk).
                const std::int64_t i = vi + (corner & 1), j = vj + ((corner >> 1) & 1), k = vk + ((corner >> 2) & 1);
                // The first foreground voxel around it in (z, y, x) order must be this one.
                bool first = true;
                for (int b = 0; b < 8 && first; ++b) {
                  const std::int64_t a = i - 1 + (b & 1), bb = j - 1 + ((b >> 1) & 1), c = k - 1 + ((b >> 2) & 1);
                  if (a == vi && bb == vj && c == vk) break;
                  first = !fg(a, bb, c);
                }
                if (!first) continue;
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
