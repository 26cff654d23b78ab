#include "mesh/surface_checks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace angiosynth {
namespace {

double orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) { return dot(cross(b - a, c - a), d - a); }

// Whether segment pq meets triangle abc (touching counts).
bool segmentMeetsTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double o1 = orient(a, b, c, p), o2 = orient(a, b, c, q);
  if ((o1 > 0 && o2 > 0) || (o1 < 0 && o2 < 0) || (o1 == 0 && o2 == 0)) return false;
  const double s1 = orient(p, q, a, b), s2 = orient(p, q, b, c), s3 = orient(p, q, c, a);
  return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

// Two triangles of a closed mesh that cross or overlap beyond what they share.
bool trianglesCross(const SurfaceMesh& m, const std::array<std::int32_t, 3>& s, const std::array<std::int32_t, 3>& t) {
  int shared = 0, si = -1, ti = -1;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (s[std::size_t(i)] == t[std::size_t(j)]) ++shared, si = i, ti = j;
  const auto P = [&](const std::array<std::int32_t, 3>& x, int i) -> const Vec3& { return m.vertices[std::size_t(x[std::size_t(i)])]; };
  if (shared == 3) return true;
  if (shared == 2) {  // folded onto each other across their edge
    const Vec3 n1 = cross(P(s, 1) - P(s, 0), P(s, 2) - P(s, 0)), n2 = cross(P(t, 1) - P(t, 0), P(t, 2) - P(t, 0));
    return dot(n1, n2) < -0.99 * norm(n1) * norm(n2);
  }
  if (shared == 1)
    return segmentMeetsTriangle(P(s, (si + 1) % 3), P(s, (si + 2) % 3), P(t, 0), P(t, 1), P(t, 2)) ||
           segmentMeetsTriangle(P(t, (ti + 1) % 3), P(t, (ti + 2) % 3), P(s, 0), P(s, 1), P(s, 2));
  for (int i = 0; i < 3; ++i) {
    if (segmentMeetsTriangle(P(s, i), P(s, (i + 1) % 3), P(t, 0), P(t, 1), P(t, 2))) return true;
    if (segmentMeetsTriangle(P(t, i), P(t, (i + 1) % 3), P(s, 0), P(s, 1), P(s, 2))) return true;
  }
  return false;
}

}  // namespace

bool closedManifold(const SurfaceMesh& m) {
  const std::size_t nv = m.vertices.size();
  std::vector<std::int32_t> start(nv + 1, 0);
  for (const auto& t : m.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || !(triangleArea(m, t) > 0)) return false;
    for (auto v : t) ++start[std::size_t(v) + 1];
  }
  for (std::size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<std::pair<std::int32_t, std::int32_t>> link(static_cast<std::size_t>(start[nv]));
  std::vector<std::int32_t> fill(start.begin(), start.end() - 1);
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k)
      link[std::size_t(fill[std::size_t(t[std::size_t(k)])]++)] = {t[std::size_t((k + 1) % 3)], t[std::size_t((k + 2) % 3)]};
  for (std::size_t v = 0; v < nv; ++v) {
    const auto first = link.begin() + start[v], last = link.begin() + start[v + 1];
    const auto n = last - first;
    if (n == 0) continue;
    if (n < 3) return false;
    std::sort(first, last);
    for (auto it = first + 1; it != last; ++it)
      if (it->first == (it - 1)->first) return false;
    std::int32_t at = first->second;
    std::ptrdiff_t steps = 1;
    while (at != first->first) {
      const auto it = std::lower_bound(first, last, std::make_pair(at, std::int32_t(-1)));
      if (it == last || it->first != at || ++steps > n) return false;
      at = it->second;
    }
    if (steps != n) return false;
  }
  return true;
}

std::vector<std::int32_t> crossingTriangles(const SurfaceMesh& m, const Vec3& origin, double cell, bool first_only, const std::vector<char>* dirty) {
  // Each triangle has a level: the bins of cell × 2^level hold its box in at most 2 per axis. A
  // pair is tested in the bins of the coarser one's level (which hold the finer one too), and
  // only in the bin of its boxes' overlap's low corner: the one where, along each axis, one of
  // the two starts. Finer triangles are binned only where a coarser one is (or, with `dirty`,
  // where a coarser one and a dirty one are).
  const std::size_t nt = m.triangles.size();
  std::vector<Vec3> box_lo(nt), box_hi(nt);
  std::vector<int> level(nt, 0);
  int top = 0;
  for (std::size_t k = 0; k < nt; ++k) {
    Vec3 lo(INFINITY, INFINITY, INFINITY), hi(-INFINITY, -INFINITY, -INFINITY);
    for (auto v : m.triangles[k]) lo = componentMin(lo, m.vertices[std::size_t(v)]), hi = componentMax(hi, m.vertices[std::size_t(v)]);
    box_lo[k] = lo, box_hi[k] = hi;
    const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    while (level[k] < 40 && cell * double(std::int64_t(1) << level[k]) < extent) ++level[k];
    top = std::max(top, level[k]);
  }
  const auto isDirty = [&](std::size_t k) { return !dirty || (*dirty)[k] != 0; };
  struct Entry {
    std::uint64_t key;
    std::int32_t triangle;
    std::uint8_t starts;  // bit a: the triangle's box starts in this bin along axis a
    bool operator<(const Entry& o) const { return key != o.key ? key < o.key : triangle < o.triangle; }
  };
  // The bins of triangle k at bin size `size`, passed to fn(key, starts).
  const auto forBins = [&](std::size_t k, double size, const auto& fn) {
    std::int64_t b0[3], b1[3];
    for (int a = 0; a < 3; ++a) {
      b0[a] = std::int64_t(std::floor((box_lo[k][a] - origin[a]) / size));
      b1[a] = std::int64_t(std::floor((box_hi[k][a] - origin[a]) / size));
    }
    for (auto z = b0[2]; z <= b1[2]; ++z)
      for (auto y = b0[1]; y <= b1[1]; ++y)
        for (auto x = b0[0]; x <= b1[0]; ++x)
          fn(std::uint64_t(x + 1) | (std::uint64_t(y + 1) << 21) | (std::uint64_t(z + 1) << 42),
             std::uint8_t((x == b0[0] ? 1 : 0) | (y == b0[1] ? 2 : 0) | (z == b0[2] ? 4 : 0)));
  };
  const auto keysOf = [](const std::vector<Entry>& entries) {
    std::vector<std::uint64_t> keys;
    for (const auto& e : entries)
      if (keys.empty() || keys.back() != e.key) keys.push_back(e.key);
    return keys;
  };
  // With `dirty`: per level l, the bins at l of the dirty triangles of level l or finer (only
  // there can a pair to test lie); and the triangles that can be in one: the dirty ones and those
  // whose box reaches such a bin, at their own level or the dirty ones' coarsest.
  std::vector<std::int32_t> candidates;
  std::vector<std::vector<std::uint64_t>> dirty_keys(std::size_t(top + 1));
  if (dirty) {
    int dirty_top = -1;
    std::vector<std::size_t> dirty_list;
    for (std::size_t k = 0; k < nt; ++k)
      if ((*dirty)[k]) dirty_top = std::max(dirty_top, level[k]), dirty_list.push_back(k);
    if (dirty_list.empty()) return {};
    for (int l = 0; l <= top; ++l) {
      auto& keys = dirty_keys[std::size_t(l)];
      for (const auto k : dirty_list)
        if (level[k] <= l) forBins(k, cell * double(std::int64_t(1) << l), [&](std::uint64_t key, std::uint8_t) { keys.push_back(key); });
      std::sort(keys.begin(), keys.end());
      keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    }
    for (std::size_t k = 0; k < nt; ++k) {
      bool take = (*dirty)[k] != 0;
      const int l = std::max(dirty_top, level[k]);
      const auto& keys = dirty_keys[std::size_t(l)];
      if (!take)
        forBins(k, cell * double(std::int64_t(1) << l),
                [&](std::uint64_t key, std::uint8_t) { take = take || std::binary_search(keys.begin(), keys.end(), key); });
      if (take) candidates.push_back(std::int32_t(k));
    }
  } else {
    candidates.resize(nt);
    for (std::size_t k = 0; k < nt; ++k) candidates[k] = std::int32_t(k);
  }
  std::vector<std::int32_t> found;
  std::vector<Entry> coarse, fine;
  for (int l = 0; l <= top; ++l) {
    const double size = cell * double(std::int64_t(1) << l);
    const auto& near = dirty_keys[std::size_t(l)];
    if (dirty && near.empty()) continue;
    coarse.clear(), fine.clear();
    for (const auto c : candidates)
      if (level[std::size_t(c)] == l)
        forBins(std::size_t(c), size, [&](std::uint64_t key, std::uint8_t starts) {
          if (!dirty || std::binary_search(near.begin(), near.end(), key)) coarse.push_back({key, c, starts});
        });
    if (coarse.empty()) continue;
    std::sort(coarse.begin(), coarse.end());
    const std::vector<std::uint64_t> keys = keysOf(coarse);
    for (const auto c : candidates)
      if (level[std::size_t(c)] < l)
        forBins(std::size_t(c), size, [&](std::uint64_t key, std::uint8_t starts) {
          if (std::binary_search(keys.begin(), keys.end(), key)) fine.push_back({key, c, starts});
        });
    std::sort(fine.begin(), fine.end());
    const auto test = [&](std::size_t a, std::size_t b, std::uint8_t starts) {
      if (starts != 7 || !(isDirty(a) || isDirty(b))) return false;
      if (box_hi[a].x < box_lo[b].x || box_hi[b].x < box_lo[a].x || box_hi[a].y < box_lo[b].y || box_hi[b].y < box_lo[a].y ||
          box_hi[a].z < box_lo[b].z || box_hi[b].z < box_lo[a].z || !trianglesCross(m, m.triangles[a], m.triangles[b]))
        return false;
      found.push_back(std::int32_t(a)), found.push_back(std::int32_t(b));
      return first_only;
    };
    std::size_t i = 0, f = 0;
    for (const auto key : keys) {
      while (coarse[i].key != key) ++i;
      std::size_t j = i;
      while (j < coarse.size() && coarse[j].key == key) ++j;
      while (f < fine.size() && fine[f].key < key) ++f;
      std::size_t g = f;
      while (g < fine.size() && fine[g].key == key) ++g;
      for (std::size_t p = i; p < j; ++p) {
        const auto a = std::size_t(coarse[p].triangle);
        for (std::size_t q = p + 1; q < j; ++q)
          if (test(a, std::size_t(coarse[q].triangle), coarse[p].starts | coarse[q].starts)) return found;
        for (std::size_t q = f; q < g; ++q)
          if (test(a, std::size_t(fine[q].triangle), coarse[p].starts | fine[q].starts)) return found;
      }
      i = j, f = g;
    }
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  return found;
}

bool freeOfCrossings(const SurfaceMesh& m, const Vec3& origin, double cell) { return crossingTriangles(m, origin, cell, true).empty(); }

}  // namespace angiosynth
