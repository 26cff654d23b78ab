#pragma once
// Points in the cubic cells of a dense grid over a box (linked lists: 4 bytes per cell and per
// point), for radius and nearest queries while points are added: space colonisation's node and
// drain searches, CCO's terminal spacing. Points outside the box fall into its border cells
// (queries measure anyway).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/vec3.hpp"

namespace angiosynth {

class PointHash {
 public:
  // `flat`: a 2D domain, one layer of cells.
  PointHash(const Vec3& lo, const Vec3& hi, double cell, bool flat) : origin_{lo.x, lo.y, lo.z}, cell_(cell), inv_(1.0 / cell) {
    const auto count = [&](double extent) { return std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(extent * inv_)) + 1); };
    n_[0] = count(hi.x - lo.x);
    n_[1] = count(hi.y - lo.y);
    n_[2] = flat ? 1 : count(hi.z - lo.z);
    // Keep the grid within 2M cells (8 MB): coarser cells for large boxes.
    while (n_[0] * n_[1] * n_[2] > (std::int64_t(1) << 21)) {
      cell_ *= 2;
      inv_ = 1.0 / cell_;
      n_[0] = count(hi.x - lo.x);
      n_[1] = count(hi.y - lo.y);
      n_[2] = flat ? 1 : count(hi.z - lo.z);
    }
    for (int a = 0; a < 3; ++a) top_[a] = double(n_[a] - 1);
    head_.assign(std::size_t(n_[0] * n_[1] * n_[2]), -1);
  }

  void insert(const Vec3& p, std::int32_t id) {
    if (std::size_t(id) >= next_.size()) next_.resize(std::size_t(id) + 1, -1);
    const auto c = index(clampCell((p.x - origin_[0]) * inv_, 0), clampCell((p.y - origin_[1]) * inv_, 1), clampCell((p.z - origin_[2]) * inv_, 2));
    if (head_[c] < 0) touched_.push_back(c);
    next_[std::size_t(id)] = head_[c];
    head_[c] = id;
  }
  // Empties the grid in the time of the cells it used.
  void clear() {
    for (auto c : touched_) head_[c] = -1;
    touched_.clear();
  }
  // Calls f(id) for every point in the cells a ball of radius r around p touches (at least every
  // point within r).
  template <class F>
  void forEachNear(const Vec3& p, double r, F&& f) const {
    anyNear(p, r, [&](std::int32_t id) {
      f(id);
      return false;
    });
  }
  // True as soon as pred(id) holds for a point of the cells the ball of radius r around p
  // touches (pred decides; every point within r is among them).
  template <class Pred>
  bool anyNear(const Vec3& p, double r, Pred&& pred) const {
    const Scan s = scan(p, r);
    for (std::int64_t z = s.lo[2]; z <= s.hi[2]; ++z)
      for (std::int64_t y = s.lo[1]; y <= s.hi[1]; ++y)
        for (std::int64_t x = s.lo[0]; x <= s.hi[0]; ++x)
          for (auto id = head_[index(x, y, z)]; id >= 0; id = next_[std::size_t(id)])
            if (pred(id)) return true;
    return false;
  }
  // The id minimising dist2(id) among points within r (ties: the smaller id), or -1. p's own cell
  // first, then the cells of the ball's box that may still hold a nearer point: once a close
  // point is known, most cells are passed over by their distance alone.
  template <class Dist2>
  std::int32_t nearest(const Vec3& p, double r, Dist2&& dist2) const {
    std::int32_t best = -1;
    double bd = r * r;
    const auto visit = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
      for (auto id = head_[index(x, y, z)]; id >= 0; id = next_[std::size_t(id)]) {
        const double d2 = dist2(id);
        if (d2 < bd || (d2 == bd && best >= 0 && id < best)) {
          bd = d2;
          best = id;
        }
      }
    };
    const Scan s = scan(p, r);
    visit(s.own[0], s.own[1], s.own[2]);
    // Squared gaps of the box's columns along x, in cells (boxes are a few cells wide).
    constexpr std::int64_t kCols = 16;
    double gx2[kCols];
    const bool listed = s.hi[0] - s.lo[0] < kCols;
    if (listed)
      for (std::int64_t x = s.lo[0]; x <= s.hi[0]; ++x) gx2[x - s.lo[0]] = sq(s.gap(0, x));
    const double c2 = cell_ * cell_;
    for (std::int64_t z = s.lo[2]; z <= s.hi[2]; ++z) {
      const double gz2 = sq(s.gap(2, z));
      for (std::int64_t y = s.lo[1]; y <= s.hi[1]; ++y) {
        const double gyz = sq(s.gap(1, y)) + gz2;
        if (gyz * c2 > bd) continue;
        for (std::int64_t x = s.lo[0]; x <= s.hi[0]; ++x) {
          const double g = gyz + (listed ? gx2[x - s.lo[0]] : sq(s.gap(0, x)));
          if (g * c2 > bd || (x == s.own[0] && y == s.own[1] && z == s.own[2])) continue;
          visit(x, y, z);
        }
      }
    }
    return best;
  }

  double cell() const { return cell_; }

 private:
  // The cells a query's ball touches along each axis, p's cell, and p in cell units.
  struct Scan {
    std::int64_t lo[3], hi[3], own[3];
    double g[3];
    // A lower bound on the distance (in cells) from p to any point of cell i along axis a: points
    // clamped into a border cell lie beyond it, and the slack covers rounding of the units (the
    // grid's 2M cells keep coordinates below 2²¹ cells, rounded to under 1e-9).
    double gap(int a, std::int64_t i) const {
      const double d = i < own[a] ? g[a] - double(i + 1) : i > own[a] ? double(i) - g[a] : 0.0;
      return d > 1e-6 ? d - 1e-6 : 0.0;
    }
  };
  static double sq(double v) { return v * v; }
  // The cell range of each axis comes from p's position in cell units ± r, widened by a
  // millionth of a cell so that rounding never leaves out a cell a point within r lies in.
  Scan scan(const Vec3& p, double r) const {
    Scan s;
    const double v[3] = {p.x, p.y, p.z}, w = r * inv_ + 1e-6;
    const int axes = n_[2] == 1 ? 2 : 3;
    for (int a = 0; a < axes; ++a) {
      const double g = s.g[a] = (v[a] - origin_[a]) * inv_;
      s.lo[a] = clampCell(g - w, a);
      s.hi[a] = clampCell(g + w, a);
      s.own[a] = clampCell(g, a);
    }
    if (axes == 2) s.lo[2] = s.hi[2] = s.own[2] = 0, s.g[2] = 0;  // one layer: no distance across it
    return s;
  }
  // The cell of a coordinate in cell units, clamped to the grid (NaN: 0). Truncation is the floor
  // of a non-negative number (floor is not inlined on baseline x86-64).
  std::int64_t clampCell(double c, int a) const { return c > 0 ? (c < top_[a] ? static_cast<std::int64_t>(c) : n_[a] - 1) : 0; }
  std::size_t index(std::int64_t x, std::int64_t y, std::int64_t z) const { return std::size_t((z * n_[1] + y) * n_[0] + x); }

  double origin_[3];
  double cell_, inv_;
  std::int64_t n_[3];
  double top_[3];  // n − 1 per axis
  std::vector<std::int32_t> head_, next_;
  std::vector<std::size_t> touched_;
};

}  // namespace angiosynth
