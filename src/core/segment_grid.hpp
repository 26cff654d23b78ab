#pragma once
// Segments (capsules) in the cells of a dense grid over a box, each listed in every cell its
// bounding box touches: a query visits only the cells of its own box, so thin vessels among
// thick ones (L-system generations, colonisation chains) cost what their neighbourhood holds,
// not what the thickest vessel's reach would sweep. Candidates are reported once per query.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "core/vec3.hpp"

namespace angiosynth {

class SegmentGrid {
 public:
  // `cell`: the edge wanted; coarser when the box would need more than 2M cells. `flat`: one layer.
  SegmentGrid(const Vec3& lo, const Vec3& hi, double cell, bool flat) : lo_(lo), cell_(std::max(cell, 1e-9)) {
    // Counts in double: a cell far below the box (a root diameter of 1e-6 mm in a 20 mm domain)
    // gives 2e10 cells per axis, whose integer product wraps round to a small number.
    const auto count = [&](double extent) { return std::max(1.0, std::ceil(extent / cell_) + 1); };
    for (;;) {
      const double nx = count(hi.x - lo.x), ny = count(hi.y - lo.y), nz = flat ? 1.0 : count(hi.z - lo.z);
      if (nx * ny * nz <= double(std::int64_t(1) << 21)) {
        n_[0] = std::int64_t(nx), n_[1] = std::int64_t(ny), n_[2] = std::int64_t(nz);
        break;
      }
      cell_ *= 1.25;
    }
    inv_ = 1 / cell_;
    head_.assign(std::size_t(n_[0] * n_[1] * n_[2]), -1);
  }

  void insert(std::int32_t id, const Vec3& a, const Vec3& b, double r) {
    forEachCell(a, b, r, [&](std::size_t c) {
      entries_.push_back({id, head_[c]});
      head_[c] = std::int32_t(entries_.size() - 1);
    });
    if (std::size_t(id) >= stamp_.size()) stamp_.resize(std::size_t(id) + 1, 0);
  }

  // Calls f(id) once for every segment listed in a cell the box of a–b grown by r touches;
  // stops when f returns true. Returns whether it stopped.
  template <class F>
  bool any(const Vec3& a, const Vec3& b, double r, F&& f) const {
    ++query_;
    bool hit = false;
    forEachCell(a, b, r, [&](std::size_t c) {
      for (auto e = head_[c]; e >= 0 && !hit; e = entries_[std::size_t(e)].next) {
        const auto id = entries_[std::size_t(e)].id;
        if (stamp_[std::size_t(id)] == query_) continue;
        stamp_[std::size_t(id)] = query_;
        hit = f(id);
      }
      return hit;
    });
    return hit;
  }

 private:
  struct Entry {
    std::int32_t id, next;
  };
  std::int64_t axis(double v, int a) const {
    const double o = a == 0 ? lo_.x : a == 1 ? lo_.y : lo_.z;
    return std::int64_t(std::clamp(std::floor((v - o) * inv_), 0.0, double(n_[a] - 1)));
  }
  // f(cell) for the cells of the box; a bool-returning f stops the walk when it returns true.
  template <class F>
  void forEachCell(const Vec3& a, const Vec3& b, double r, F&& f) const {
    const std::int64_t x0 = axis(std::min(a.x, b.x) - r, 0), x1 = axis(std::max(a.x, b.x) + r, 0);
    const std::int64_t y0 = axis(std::min(a.y, b.y) - r, 1), y1 = axis(std::max(a.y, b.y) + r, 1);
    const std::int64_t z0 = axis(std::min(a.z, b.z) - r, 2), z1 = axis(std::max(a.z, b.z) + r, 2);
    for (std::int64_t z = z0; z <= z1; ++z)
      for (std::int64_t y = y0; y <= y1; ++y)
        for (std::int64_t x = x0; x <= x1; ++x) {
          const std::size_t c = std::size_t((z * n_[1] + y) * n_[0] + x);
          if constexpr (std::is_same_v<decltype(f(c)), bool>) {
            if (f(c)) return;
          } else {
            f(c);
          }
        }
  }

  Vec3 lo_;
  double cell_, inv_ = 1;
  std::int64_t n_[3];
  std::vector<std::int32_t> head_;
  std::vector<Entry> entries_;
  mutable std::vector<std::uint32_t> stamp_;
  mutable std::uint32_t query_ = 0;
};

}  // namespace angiosynth
