#pragma once
// Points in the cubic cells of a dense grid over a box (linked lists: 4 bytes per cell and per
// point), for radius and nearest queries while points are added: space colonisation's node and
// drain searches. Points outside the box fall into its border cells (queries measure anyway).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/vec3.hpp"

namespace angiosynth {

class PointHash {
 public:
  // `flat`: a 2D domain, one layer of cells.
  PointHash(const Vec3& lo, const Vec3& hi, double cell, bool flat) : lo_(lo), cell_(cell), inv_(1.0 / cell) {
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
    head_.assign(std::size_t(n_[0] * n_[1] * n_[2]), -1);
  }

  void insert(const Vec3& p, std::int32_t id) {
    if (std::size_t(id) >= next_.size()) next_.resize(std::size_t(id) + 1, -1);
    const auto c = index(axis(p.x, 0), axis(p.y, 1), axis(p.z, 2));
    if (head_[c] < 0) touched_.push_back(c);
    next_[std::size_t(id)] = head_[c];
    head_[c] = id;
  }
  // Empties the grid in the time of the cells it used.
  void clear() {
    for (auto c : touched_) head_[c] = -1;
    touched_.clear();
  }
  // Calls f(id) for every point in the cells a ball of radius r around p touches.
  template <class F>
  void forEachNear(const Vec3& p, double r, F&& f) const {
    anyNear(p, r, [&](std::int32_t id) {
      f(id);
      return false;
    });
  }
  // True as soon as pred(id) holds for a point in the cells a ball of radius r around p touches.
  template <class Pred>
  bool anyNear(const Vec3& p, double r, Pred&& pred) const {
    const std::int64_t x0 = axis(p.x - r, 0), x1 = axis(p.x + r, 0), y0 = axis(p.y - r, 1), y1 = axis(p.y + r, 1), z0 = axis(p.z - r, 2),
                       z1 = axis(p.z + r, 2);
    for (std::int64_t z = z0; z <= z1; ++z)
      for (std::int64_t y = y0; y <= y1; ++y)
        for (std::int64_t x = x0; x <= x1; ++x)
          for (auto id = head_[index(x, y, z)]; id >= 0; id = next_[std::size_t(id)])
            if (pred(id)) return true;
    return false;
  }
  // The id minimising dist2(id) among points within r (ties: the smaller id), or -1. Cells are
  // visited in rings around p's cell and the search stops once the next ring is farther than the
  // best point: in a dense cloud the nearest point is found in a few cells whatever r is.
  template <class Dist2>
  std::int32_t nearest(const Vec3& p, double r, Dist2&& dist2) const {
    std::int32_t best = -1;
    double bd = r * r;
    const auto consider = [&](std::int32_t id) {
      const double d2 = dist2(id);
      if (d2 < bd || (d2 == bd && best >= 0 && id < best)) {
        bd = d2;
        best = id;
      }
    };
    const auto visit = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
      for (auto id = head_[index(x, y, z)]; id >= 0; id = next_[std::size_t(id)]) consider(id);
    };
    const std::int64_t lo[3] = {axis(p.x - r, 0), axis(p.y - r, 1), axis(p.z - r, 2)};
    const std::int64_t hi[3] = {axis(p.x + r, 0), axis(p.y + r, 1), axis(p.z + r, 2)};
    // p's position in cell units; the ring bound holds for p inside the grid (points clamped into
    // a border cell lie beyond it, no nearer to an inside p than the cell itself).
    const double g[3] = {(p.x - lo_.x) * inv_, (p.y - lo_.y) * inv_, (p.z - lo_.z) * inv_};
    const int axes = n_[2] == 1 ? 2 : 3;
    bool inside = true;
    for (int a = 0; a < axes; ++a) inside = inside && g[a] >= 0 && g[a] < double(n_[a]);
    if (!inside) {
      forEachNear(p, r, consider);
      return best;
    }
    std::int64_t c[3] = {0, 0, 0};
    std::int64_t rings = 0;
    for (int a = 0; a < axes; ++a) {
      c[a] = std::min<std::int64_t>(static_cast<std::int64_t>(g[a]), n_[a] - 1);
      rings = std::max({rings, c[a] - lo[a], hi[a] - c[a]});
    }
    for (std::int64_t k = 0; k <= rings; ++k) {
      if (k > 0) {
        // Every point of ring k lies outside the block of cells within k − 1 of p's cell.
        double gap = INFINITY;
        for (int a = 0; a < axes; ++a) gap = std::min({gap, g[a] - double(c[a] - k + 1), double(c[a] + k) - g[a]});
        gap *= cell_ * (1 - 1e-12);
        if (gap * gap > bd) break;
      }
      const std::int64_t z0 = std::max(lo[2], c[2] - k), z1 = std::min(hi[2], c[2] + k);
      const std::int64_t y0 = std::max(lo[1], c[1] - k), y1 = std::min(hi[1], c[1] + k);
      const std::int64_t x0 = std::max(lo[0], c[0] - k), x1 = std::min(hi[0], c[0] + k);
      for (std::int64_t z = z0; z <= z1; ++z)
        for (std::int64_t y = y0; y <= y1; ++y) {
          if (std::abs(z - c[2]) == k || std::abs(y - c[1]) == k) {
            for (std::int64_t x = x0; x <= x1; ++x) visit(x, y, z);
            continue;
          }
          if (c[0] - k >= x0) visit(c[0] - k, y, z);
          if (k > 0 && c[0] + k <= x1) visit(c[0] + k, y, z);
        }
    }
    return best;
  }

  double cell() const { return cell_; }

 private:
  // floor((v − o)/cell) clamped to the grid, without calling floor (not inlined on baseline
  // x86-64): truncation is the floor of a non-negative number.
  std::int64_t axis(double v, int a) const {
    const double o = a == 0 ? lo_.x : a == 1 ? lo_.y : lo_.z;
    const double c = (v - o) * inv_;
    if (!(c >= 0)) return 0;
    const double top = double(n_[a] - 1);
    return c >= top ? n_[a] - 1 : static_cast<std::int64_t>(c);
  }
  std::size_t index(std::int64_t x, std::int64_t y, std::int64_t z) const { return std::size_t((z * n_[1] + y) * n_[0] + x); }

  Vec3 lo_;
  double cell_, inv_;
  std::int64_t n_[3];
  std::vector<std::int32_t> head_, next_;
  std::vector<std::size_t> touched_;
};

}  // namespace angiosynth
