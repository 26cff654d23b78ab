#include "mesh/hollow_wall.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "core/error.hpp"
#include "mesh/ring_mesh.hpp"
#include "mesh/vessel_ends.hpp"

namespace angiosynth {
namespace {}  // namespace

SurfaceMesh hollowWall(const VascularTree& tree, const TubeSurfaceOptions& options, const WallThickness& wall, HollowWallReport* report,
                       const std::function<void(std::int64_t, std::int64_t)>& progress) {
  HollowWallReport local;
  HollowWallReport& rep = report ? *report : local;
  rep = HollowWallReport();
  // The outer tree: every vessel thickened by its wall at each end.
  VascularTree outer = tree;
  double thickest = 0;  // the largest radius / wall ratio: the contours' steps must stay under the wall
  const auto wallAt = [&](std::int32_t s, bool start) {
    const double r = start ? tree.startRadius(s) : tree.radius[s];
    const double own = start && tree.wall_start[s] > 0 ? tree.wall_start[s] : tree.wall[s];
    const double w = wall.at(r, own);
    if (!(w > 0) || !std::isfinite(w))
      throw InputError("", 0,
                       "vessel " + std::to_string(s) + " has no wall thickness (" + std::to_string(w) +
                           " mm); allowed: a thickness > 0 for every vessel (a graph's wall values, a ratio or a constant)");
    thickest = std::max(thickest, r / w);
    return w;
  };
  for (std::int32_t s = 0; s < tree.nodeCount(); ++s) {
    if (tree.isRoot(s) || tree.isLink(s)) continue;
    const double ra = tree.startRadius(s) + wallAt(s, true), rb = tree.radius[s] + wallAt(s, false);
    outer.radius[s] = rb;
    outer.radius_start[s] = ra != rb ? ra : -1;
  }
  for (std::int32_t s = 0; s < tree.nodeCount(); ++s)
    if (tree.isLink(s)) outer.radius[s] = tree.radius[s] + wallAt(s, false);
  // Both sides within a small share of the wall of their vessels: contoured with cells no
  // larger than the wall where vessels meet (a chord stands c²/8r inside), rings with enough
  // vertices that a chord stands at most kRingShare of the wall inside (per vessel for a
  // constant wall, per tree for one in proportion to the radius).
  constexpr double kRingShare = 0.02;
  TubeSurfaceOptions lumen_o = options, outer_o = options;
  for (auto* o : {&lumen_o, &outer_o}) {
    if (wall.constant_mm > 0) {
      o->junction.max_cell_mm = wall.constant_mm;
      o->ring_tolerance_mm = kRingShare * wall.constant_mm;
    } else {
      o->junction.samples_across = std::max(options.junction.samples_across, int(std::ceil(2 * thickest)));
      o->ring_vertices = std::max({o->ring_vertices, o->min_ring_vertices, int(std::ceil(std::numbers::pi / std::acos(1 - kRingShare / thickest)))});
    }
    o->cap_ends = false;
  }
  // Every end open on both sides, or closed (round) on both: an end one side cannot cut (its
  // vessel ends against another) is taken out and both are built again, so the lumen ends inside
  // the wall there.
  std::vector<std::size_t> open;  // indices into options.ends
  for (std::size_t e = 0; e < options.ends.size(); ++e) open.push_back(e);
  SurfaceMesh m, lumen;
  std::vector<std::vector<std::int32_t>> outer_loops, lumen_loops;
  for (;;) {
    outer_o.ends.clear();
    lumen_o.ends.clear();
    for (auto e : open) {
      lumen_o.ends.push_back(options.ends[e]);
      outer_o.ends.push_back(options.ends[e]);
      outer_o.ends.back().radius += wallAt(options.ends[e].vessel, options.ends[e].root);
    }
    m = tubeSurface(outer, outer_o, &rep.outer, progress);
    lumen = tubeSurface(tree, lumen_o, &rep.lumen, progress);
    outer_loops = starLoops(m, outer_o.ends);
    lumen_loops = starLoops(lumen, lumen_o.ends);
    std::vector<std::size_t> still;
    for (std::size_t k = 0; k < open.size(); ++k) {
      if (!outer_loops[k].empty() && !lumen_loops[k].empty())
        still.push_back(open[k]);
      else
        rep.not_joined.push_back(std::int32_t(open[k]));
    }
    if (still.size() == open.size()) break;
    open = std::move(still);
  }
  std::sort(rep.not_joined.begin(), rep.not_joined.end());
  // The lumen turned inside out, after the outer side.
  const auto base = std::int32_t(m.vertices.size());
  m.vertices.insert(m.vertices.end(), lumen.vertices.begin(), lumen.vertices.end());
  m.vertex_step.insert(m.vertex_step.end(), lumen.vertex_step.begin(), lumen.vertex_step.end());
  if (m.triangle_face.empty()) m.triangle_face.assign(m.triangles.size(), 0);
  for (std::size_t k = 0; k < lumen.triangles.size(); ++k) {
    const auto& t = lumen.triangles[k];
    m.triangles.push_back({t[0] + base, t[2] + base, t[1] + base});
    m.triangle_tree.push_back(lumen.triangle_tree[k]);
    m.triangle_face.push_back(0);
  }
  // Each open end: a flat ring from the outer loop in to the lumen's, facing along its normal.
  for (std::size_t k = 0; k < open.size(); ++k) {
    const auto& end = options.ends[open[k]];
    auto inner = lumen_loops[k];
    for (auto& p : inner) p += base;
    zipRings(m, end.centre, end.normal, outer_loops[k], inner, end.tree, std::int32_t(open[k]) + 1);
    ++rep.rings;
  }
  return m;
}

}  // namespace angiosynth
