#include "core/distance_transform.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace angiosynth {
namespace {

// Squared distances along one line of n points and spacing h to the nearest site (f: squared
// distance at the line's own points so far; 0 at sites); v and z are scratch of n and n + 1.
void edt1d(const double* f, int n, double h, double* d, int* v, double* z) {
  int k = 0;
  v[0] = 0;
  // Infinite sentinels: with a spacing below ½ an intersection can lie beyond ±kFarSquared.
  z[0] = -INFINITY;
  z[1] = INFINITY;
  const auto at = [h](int q) { return double(q) * h; };
  for (int q = 1; q < n; ++q) {
    double s = ((f[q] + at(q) * at(q)) - (f[v[k]] + at(v[k]) * at(v[k]))) / (2.0 * (at(q) - at(v[k])));
    while (s <= z[k]) {
      --k;
      s = ((f[q] + at(q) * at(q)) - (f[v[k]] + at(v[k]) * at(v[k]))) / (2.0 * (at(q) - at(v[k])));
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = INFINITY;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < at(q)) ++k;
    d[q] = (at(q) - at(v[k])) * (at(q) - at(v[k])) + f[v[k]];
  }
}

// Lines along y and z are read as blocks of this many lines adjacent in x: one cache line of
// doubles serves all of them, where a line alone would touch a cache line (and, along z, a
// page) per point.
constexpr int kLinesPerBlock = 8;

}  // namespace

void squaredDistances(std::vector<double>& g, const std::array<int, 3>& n, const std::array<double, 3>& h, int axes) {
  for (int axis = 0; axis < axes; ++axis) {
    // The lines along `axis`, indexed by their two other coordinates a (x unless the lines run
    // along x) and b.
    const int a = axis == 0 ? 1 : 0, b = axis == 2 ? 1 : 2;
    const int len = n[axis], na = n[a];
    const std::size_t stride[3] = {1, std::size_t(n[0]), std::size_t(n[0]) * n[1]};
    const std::size_t step = stride[axis], sa = stride[a], sb = stride[b];
    const int width = sa == 1 ? kLinesPerBlock : 1;
    const std::size_t blocks_a = std::size_t((na + width - 1) / width);
    const std::size_t blocks = blocks_a * std::size_t(n[b]);
    const double spacing = h[axis];
    double* data = g.data();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks), [=](const tbb::blocked_range<std::size_t>& r) {
      // Line j of a block at f[j·len …], its distances at d[j·len …].
      std::vector<double> f(std::size_t(len) * width), d(std::size_t(len) * width), z(std::size_t(len) + 1);
      std::vector<int> v(static_cast<std::size_t>(len));
      for (std::size_t block = r.begin(); block != r.end(); ++block) {
        const int first = int(block % blocks_a) * width, lines = std::min(width, na - first);
        double* p = data + std::size_t(first) * sa + (block / blocks_a) * sb;
        for (int q = 0; q < len; ++q)
          for (int j = 0; j < lines; ++j) f[std::size_t(j) * len + q] = p[std::size_t(q) * step + std::size_t(j) * sa];
        for (int j = 0; j < lines; ++j) {
          double* fj = f.data() + std::size_t(j) * len;
          double* dj = d.data() + std::size_t(j) * len;
          bool any = false;
          for (int q = 0; q < len; ++q) any |= fj[q] < kFarSquared;
          if (any)
            edt1d(fj, len, spacing, dj, v.data(), z.data());
          else  // no site reaches this line yet: it stays far
            std::copy(fj, fj + len, dj);
        }
        for (int q = 0; q < len; ++q)
          for (int j = 0; j < lines; ++j) p[std::size_t(q) * step + std::size_t(j) * sa] = d[std::size_t(j) * len + q];
      }
    });
  }
}

}  // namespace angiosynth
