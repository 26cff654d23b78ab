#include "core/segment_index.hpp"

#include <algorithm>
#include <cmath>

namespace angiosynth {

void SegmentIndex::refresh(const VascularTree& tree, bool force) {
  const auto n = tree.segmentCount();
  if (!force && cell_ > 0 && n < 2 * std::max<std::int32_t>(built_for_, 8)) return;
  build(tree, cellSizeFor(n));
}

double SegmentIndex::cellSizeFor(std::int64_t n) const {
  const Vec3 ext = hi_ - lo_;
  // About two segments per cell on average; never more than ~2^22 cells.
  // A box without thickness (a 2D tree's, given flat) is planar whatever the caller said: its
  // volume would give cells of no size.
  if (planar_ || !(ext.z > 1e-9 * std::max(ext.x, ext.y))) {
    const double area = std::max(ext.x * ext.y, 1e-30);
    return std::max(std::sqrt(2.0 * area / double(std::max<std::int64_t>(n, 1))), std::sqrt(area / double(1 << 22)));
  }
  const double volume = std::max(ext.x * ext.y * ext.z, 1e-30);
  return std::max(std::cbrt(2.0 * volume / double(std::max<std::int64_t>(n, 1))), std::cbrt(volume / double(1 << 22)));
}

void SegmentIndex::rebuild(const VascularTree& tree, std::span<const std::int32_t> segments) {
  clear(tree, cellSizeFor(std::int64_t(segments.size())));
  for (const auto s : segments) insert(tree, s);
}

void SegmentIndex::build(const VascularTree& tree, double cell) {
  clear(tree, cell);
  for (std::int32_t s = 1; s < tree.nodeCount(); ++s)
    if (!tree.isRoot(s)) insert(tree, s);
}

void SegmentIndex::clear(const VascularTree& tree, double cell) {
  cell_ = cell;
  journal_.clear();  // a rebuild keeps what it finds: nothing left to take back
  journaling_ = false;
  const Vec3 ext = hi_ - lo_;
  for (int ax = 0; ax < 3; ++ax) n_[ax] = std::max(1, static_cast<int>(std::ceil(ext[ax] / cell_)));
  cells_.assign(std::size_t(n_[0]) * n_[1] * n_[2], {});
  built_for_ = tree.segmentCount();
}

void SegmentIndex::cellRange(const Vec3& lo, const Vec3& hi, int* a, int* b) const {
  for (int ax = 0; ax < 3; ++ax) {
    a[ax] = std::clamp(static_cast<int>(std::floor((lo[ax] - lo_[ax]) / cell_)), 0, n_[ax] - 1);
    b[ax] = std::clamp(static_cast<int>(std::floor((hi[ax] - lo_[ax]) / cell_)), 0, n_[ax] - 1);
  }
}

void SegmentIndex::insert(const VascularTree& tree, std::int32_t s) {
  const Vec3& p = tree.position[tree.parent[s]];
  const Vec3& q = tree.position[s];
  int a[3], b[3];
  cellRange(Vec3(std::min(p.x, q.x), std::min(p.y, q.y), std::min(p.z, q.z)), Vec3(std::max(p.x, q.x), std::max(p.y, q.y), std::max(p.z, q.z)), a, b);
  // A long diagonal segment touches only a thin line of its box: test each cell's distance.
  const double half_diag = 0.5 * std::sqrt(3.0) * cell_;
  const bool big = (b[0] - a[0] + 1) * (b[1] - a[1] + 1) * (b[2] - a[2] + 1) > 8;
  for (int k = a[2]; k <= b[2]; ++k)
    for (int j = a[1]; j <= b[1]; ++j)
      for (int i = a[0]; i <= b[0]; ++i) {
        if (big) {
          const Vec3 c = lo_ + Vec3(i + 0.5, j + 0.5, k + 0.5) * cell_;
          if (pointSegmentDistance(c, p, q) > half_diag) continue;
        }
        cells_[cellId(i, j, k)].push_back(s);
        if (journaling_) journal_.push_back(cellId(i, j, k));
      }
}

void SegmentIndex::endTrial(bool keep) {
  // Each journalled entry is the last of its cell once the later ones are popped.
  if (!keep)
    for (auto it = journal_.rbegin(); it != journal_.rend(); ++it) cells_[std::size_t(*it)].pop_back();
  journal_.clear();
  journaling_ = false;
}

void SegmentIndex::nearest(const VascularTree& tree, const Vec3& p, int k, std::vector<std::pair<double, std::int32_t>>& out) {
  out.clear();
  const auto nseg = tree.segmentCount();
  if (nseg == 0 || k <= 0) return;
  k = std::min<int>(k, nseg);
  int c[3];
  cellOf(p, c);
  // Distance from p to the outside of the block of cells within Chebyshev ring r.
  double margin[3][2];
  for (int ax = 0; ax < 3; ++ax) {
    margin[ax][0] = p[ax] - (lo_[ax] + c[ax] * cell_);
    margin[ax][1] = lo_[ax] + (c[ax] + 1) * cell_ - p[ax];
  }
  ++marks_.stamp;
  const int max_ring = std::max({n_[0], n_[1], n_[2]});
  for (int r = 0; r <= max_ring; ++r) {
    for (int kk = c[2] - r; kk <= c[2] + r; ++kk) {
      if (kk < 0 || kk >= n_[2]) continue;
      for (int jj = c[1] - r; jj <= c[1] + r; ++jj) {
        if (jj < 0 || jj >= n_[1]) continue;
        const bool face = kk == c[2] - r || kk == c[2] + r || jj == c[1] - r || jj == c[1] + r;
        for (int ii = c[0] - r; ii <= c[0] + r; ii += (face || r == 0) ? 1 : 2 * r) {
          if (ii < 0 || ii >= n_[0]) continue;
          for (auto s : cells_[cellId(ii, jj, kk)]) {
            if (!marks_.mark(s)) continue;
            const double d = pointSegmentDistance(p, tree.position[tree.parent[s]], tree.position[s]);
            if (static_cast<int>(out.size()) < k || d < out.back().first || (d == out.back().first && s < out.back().second)) {
              const std::pair<double, std::int32_t> e{d, s};
              out.insert(std::upper_bound(out.begin(), out.end(), e), e);
              if (static_cast<int>(out.size()) > k) out.pop_back();
            }
          }
        }
      }
    }
    if (static_cast<int>(out.size()) == k) {
      // Everything not yet visited lies beyond ring r.
      double reach = 1e300;
      for (int ax = 0; ax < 3; ++ax) {
        if (c[ax] - r > 0) reach = std::min(reach, margin[ax][0] + r * cell_);
        if (c[ax] + r < n_[ax] - 1) reach = std::min(reach, margin[ax][1] + r * cell_);
      }
      if (out.back().first <= reach) return;
    }
  }
}

bool SegmentIndex::anyWithin(const VascularTree& tree, const Vec3& p, double radius) {
  // Rings of cells outward from p's cell, so that the usual hit (a segment close by) returns
  // after a few cells; a segment within `radius` has its closest point, and so a registered
  // cell, within ring ⌈radius / cell⌉.
  ++marks_.stamp;
  int c[3];
  for (int ax = 0; ax < 3; ++ax) {
    const double u = (p[ax] - lo_[ax]) / cell_;
    if (!(u >= 0 && u < n_[ax])) {
      int a[3], b[3];
      const Vec3 r(radius, radius, radius);
      cellRange(p - r, p + r, a, b);
      for (int k = a[2]; k <= b[2]; ++k)
        for (int j = a[1]; j <= b[1]; ++j)
          for (int i = a[0]; i <= b[0]; ++i)
            for (auto s : cells_[cellId(i, j, k)])
              if (marks_.mark(s) && pointSegmentDistance(p, tree.position[tree.parent[s]], tree.position[s]) < radius) return true;
      return false;
    }
    c[ax] = static_cast<int>(u);
  }
  const int rings = std::min(static_cast<int>(std::ceil(radius / cell_)), std::max({n_[0], n_[1], n_[2]}));
  for (int r = 0; r <= rings; ++r)
    for (int kk = std::max(0, c[2] - r); kk <= std::min(n_[2] - 1, c[2] + r); ++kk)
      for (int jj = std::max(0, c[1] - r); jj <= std::min(n_[1] - 1, c[1] + r); ++jj) {
        const bool face = kk == c[2] - r || kk == c[2] + r || jj == c[1] - r || jj == c[1] + r;
        for (int ii = c[0] - r; ii <= c[0] + r; ii += (face || r == 0) ? 1 : 2 * r) {
          if (ii < 0 || ii >= n_[0]) continue;
          for (auto s : cells_[cellId(ii, jj, kk)])
            if (marks_.mark(s) && pointSegmentDistance(p, tree.position[tree.parent[s]], tree.position[s]) < radius) return true;
        }
      }
  return false;
}

}  // namespace angiosynth
