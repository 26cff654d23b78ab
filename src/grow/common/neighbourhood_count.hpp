#pragma once
// "Is there any point within distance c of p?" in one memory read: cells of side c each count
// the points in the block of 3×3 (2D) or 3×3×3 cells around them. A point within c of p lies in
// the block around p's cell, so a zero count proves that none is. Space colonisation asks this
// of every candidate drain; far from the trees a search would scan dozens of empty cells.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/vec3.hpp"

namespace angiosynth {

class NeighbourhoodCount {
 public:
  // Not built yet: counts nothing and answers "may be near" to every question.
  NeighbourhoodCount() = default;
  // `flat`: a 2D domain, one layer of cells. Cells come out a little larger than `cell` (rounding
  // in the cell index must not move a point at distance just under `cell` out of the block), and
  // larger still for a big box (the grid keeps within 2M cells): both keep every answer true.
  NeighbourhoodCount(const Vec3& lo, const Vec3& hi, double cell, bool flat) : lo_(lo), inv_(1.0 / (cell * (1 + 1e-6))) {
    const auto count = [&](double extent) { return std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(extent * inv_)) + 1); };
    for (;;) {
      n_[0] = count(hi.x - lo.x);
      n_[1] = count(hi.y - lo.y);
      n_[2] = flat ? 1 : count(hi.z - lo.z);
      if (n_[0] * n_[1] * n_[2] <= (std::int64_t(1) << 21)) break;
      inv_ /= 2;
    }
    for (int a = 0; a < 3; ++a) top_[a] = double(n_[a] - 1);
    count_.assign(std::size_t(n_[0] * n_[1] * n_[2]), 0);
  }

  void insert(const Vec3& p) {
    if (count_.empty()) return;
    const std::int64_t c[3] = {axis(p.x, 0), axis(p.y, 1), axis(p.z, 2)};
    const std::int64_t z0 = std::max<std::int64_t>(0, c[2] - 1), z1 = std::min(n_[2] - 1, c[2] + 1);
    const std::int64_t y0 = std::max<std::int64_t>(0, c[1] - 1), y1 = std::min(n_[1] - 1, c[1] + 1);
    const std::int64_t x0 = std::max<std::int64_t>(0, c[0] - 1), x1 = std::min(n_[0] - 1, c[0] + 1);
    for (std::int64_t z = z0; z <= z1; ++z)
      for (std::int64_t y = y0; y <= y1; ++y)
        for (std::int64_t x = x0; x <= x1; ++x) ++count_[index(x, y, z)];
  }
  // False: no point lies within `cell` (as constructed) of p; true: one may.
  bool mayBeNear(const Vec3& p) const { return count_.empty() || count_[index(axis(p.x, 0), axis(p.y, 1), axis(p.z, 2))] != 0; }

 private:
  // Points outside the box count in its border cells: clamping never moves a point's cell
  // farther from a cell inside the grid, so the block test stays a proof.
  std::int64_t axis(double v, int a) const {
    if (a == 2 && n_[2] == 1) return 0;
    const double o = a == 0 ? lo_.x : a == 1 ? lo_.y : lo_.z;
    const double c = (v - o) * inv_;
    if (!(c >= 0)) return 0;
    return c >= top_[a] ? n_[a] - 1 : static_cast<std::int64_t>(c);
  }
  std::size_t index(std::int64_t x, std::int64_t y, std::int64_t z) const { return std::size_t((z * n_[1] + y) * n_[0] + x); }

  Vec3 lo_;
  double inv_ = 1;
  std::int64_t n_[3] = {1, 1, 1};
  double top_[3] = {0, 0, 0};  // n − 1 per axis
  std::vector<std::int32_t> count_;
};

}  // namespace angiosynth
