#pragma once
// Uniform grid over the domain that lists, per cell, the segments whose bounding box touches it.
// The cell size follows the mean segment spacing (the grid is rebuilt whenever the segment count
// doubles), so nearest-segment and neighbourhood queries cost O(1) on average and rebuilding
// costs O(1) amortised per insertion. A split segment keeps its id and only shrinks, so stale
// cell entries are harmless: queries always measure the segment's current geometry.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <span>
#include <vector>

#include "core/vascular_tree.hpp"

namespace angiosynth {

class SegmentIndex {
 public:
  // `planar`: the domain is a slab one cell thick (2D trees); cells follow the area.
  SegmentIndex(const Vec3& domain_lo, const Vec3& domain_hi, bool planar = false) : lo_(domain_lo), hi_(domain_hi), planar_(planar) {}

  // Rebuilds when the tree has doubled since the last build (or on `force`).
  void refresh(const VascularTree& tree, bool force = false);
  // Rebuilds holding only `segments`, with cells sized for their number.
  void rebuild(const VascularTree& tree, std::span<const std::int32_t> segments);
  void insert(const VascularTree& tree, std::int32_t segment);
  // Insertions between beginTrial() and endTrial(false) are taken back: a grower that inserts a
  // trial's segments before checking them leaves nothing behind when it rolls the trial back
  // (thousands of stale entries would otherwise crowd the cells it keeps querying).
  void beginTrial() {
    journal_.clear();
    journaling_ = true;
  }
  void endTrial(bool keep);

  // The k segments nearest to p (point–segment distance), nearest first: (distance, id).
  void nearest(const VascularTree& tree, const Vec3& p, int k, std::vector<std::pair<double, std::int32_t>>& out);
  // True if within(id, distance) holds for a segment registered in p's own cell: a look at a few
  // segments before any search.
  template <class F>
  bool anyInCell(const VascularTree& tree, const Vec3& p, F&& within) const {
    if (!(cell_ > 0)) return false;
    int c[3];
    cellOf(p, c);
    for (auto s : cells_[cellId(c[0], c[1], c[2])])
      if (within(s, pointSegmentDistance(p, tree.position[tree.parent[s]], tree.position[s]))) return true;
    return false;
  }
  // True if some segment lies closer than `radius` to p.
  bool anyWithin(const VascularTree& tree, const Vec3& p, double radius);
  // Which segments a query has already met; one per concurrent caller of the const queries.
  struct Marks {
    std::vector<std::uint32_t> stamps;
    std::uint32_t stamp = 0;
    bool mark(std::int32_t s) {
      if (s >= static_cast<std::int32_t>(stamps.size())) stamps.resize(2 * std::size_t(s) + 16, 0);
      if (stamps[std::size_t(s)] == stamp) return false;
      stamps[std::size_t(s)] = stamp;
      return true;
    }
  };

  // Calls f(id) once for every segment whose cells overlap the box [lo, hi].
  template <class F>
  void forEachInBox(const Vec3& lo, const Vec3& hi, F&& f) {
    int a[3], b[3];
    cellRange(lo, hi, a, b);
    ++marks_.stamp;
    for (int k = a[2]; k <= b[2]; ++k)
      for (int j = a[1]; j <= b[1]; ++j)
        for (int i = a[0]; i <= b[0]; ++i)
          for (auto s : cells_[cellId(i, j, k)])
            if (marks_.mark(s)) f(s);
  }
  // Calls f(id) once for every segment registered in a cell within `reach` of segment a–b.
  template <class F>
  void forEachNearSegment(const Vec3& a, const Vec3& b, double reach, F&& f) {
    forEachNearSegment(a, b, reach, marks_, f);
  }
  // The same for one of several threads querying at once, each with its own marks.
  template <class F>
  void forEachNearSegment(const Vec3& a, const Vec3& b, double reach, Marks& marks, F&& f) const {
    int lo[3], hi[3];
    const Vec3 r(reach, reach, reach);
    cellRange(Vec3(std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)) - r,
              Vec3(std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)) + r, lo, hi);
    const double limit = reach + 0.8660254037844387 * cell_;
    const bool big = (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1) > 27;
    ++marks.stamp;
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          if (big && pointSegmentDistance(lo_ + Vec3(i + 0.5, j + 0.5, k + 0.5) * cell_, a, b) > limit) continue;
          for (auto s : cells_[cellId(i, j, k)])
            if (marks.mark(s)) f(s);
        }
  }
  double cellSize() const { return cell_; }
  // Entries over all cells (a segment counts once per cell it touches).
  std::size_t entryCount() const {
    std::size_t n = 0;
    for (const auto& c : cells_) n += c.size();
    return n;
  }

 private:
  void build(const VascularTree& tree, double cell);
  double cellSizeFor(std::int64_t segments) const;
  void clear(const VascularTree& tree, double cell);  // no entries, cells of the given size
  void cellRange(const Vec3& lo, const Vec3& hi, int* a, int* b) const;
  // The cell holding p, or the nearest one for a point outside the grid.
  void cellOf(const Vec3& p, int* c) const {
    for (int ax = 0; ax < 3; ++ax) c[ax] = std::clamp(static_cast<int>(std::floor((p[ax] - lo_[ax]) / cell_)), 0, n_[ax] - 1);
  }
  std::int64_t cellId(int i, int j, int k) const { return i + std::int64_t(n_[0]) * (j + std::int64_t(n_[1]) * k); }

  Vec3 lo_, hi_;
  bool planar_ = false;
  double cell_ = 0;
  int n_[3] = {0, 0, 0};
  std::vector<std::vector<std::int32_t>> cells_;
  Marks marks_;
  std::int32_t built_for_ = 0;
  std::vector<std::int64_t> journal_;  // cells appended to since beginTrial(), in order
  bool journaling_ = false;
};

}  // namespace angiosynth
