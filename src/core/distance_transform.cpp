#include "core/distance_transform.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstddef>

namespace angiosynth {
namespace {

// Squared distances along one line of spacing h to the nearest site (f: squared distance at the
// line's own points so far; 0 at sites).
void edt1d(const std::vector<double>& f, double h, std::vector<double>& d, std::vector<int>& v, std::vector<double>& z) {
  const int n = int(f.size());
  v.assign(n, 0);
  z.assign(n + 1, 0);
  int k = 0;
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
  d.resize(n);
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < at(q)) ++k;
    d[q] = (at(q) - at(v[k])) * (at(q) - at(v[k])) + f[v[k]];
  }
}

}  // namespace

void squaredDistances(std::vector<double>& g, const std::array<int, 3>& n, const std::array<double, 3>& h, int axes) {
  for (int axis = 0; axis < axes; ++axis) {
    // The lines along `axis`, indexed by their two other coordinates.
    const int a = axis == 0 ? 1 : 0, b = axis == 2 ? 1 : 2;
    const int len = n[axis], na = n[a];
    const std::size_t lines = std::size_t(n[a]) * n[b];
    const std::size_t stride[3] = {1, std::size_t(n[0]), std::size_t(n[0]) * n[1]};
    const std::size_t step = stride[axis], sa = stride[a], sb = stride[b];
    const double spacing = h[axis];
    double* data = g.data();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, lines), [=](const tbb::blocked_range<std::size_t>& r) {
      std::vector<double> f(static_cast<std::size_t>(len)), d, z;
      std::vector<int> v;
      for (std::size_t line = r.begin(); line != r.end(); ++line) {
        double* p = data + (line % std::size_t(na)) * sa + (line / std::size_t(na)) * sb;
        bool any = false;
        for (int q = 0; q < len; ++q) any |= (f[std::size_t(q)] = p[std::size_t(q) * step]) < kFarSquared;
        if (!any) continue;  // no site reaches this line yet: it stays far
        edt1d(f, spacing, d, v, z);
        for (int q = 0; q < len; ++q) p[std::size_t(q) * step] = d[std::size_t(q)];
      }
    });
  }
}

}  // namespace angiosynth
