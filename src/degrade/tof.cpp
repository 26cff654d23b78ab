// Time-of-flight MR angiography: blood is bright because it flows in unsaturated, and loses that
// signal with every excitation it meets on its way (inflow saturation); multi-slab acquisitions
// repeat the loss slab by slab, so intensities step at slab borders (the venetian-blind artefact).
#include <algorithm>
#include <cmath>
#include <deque>
#include <vector>

#include <tbb/parallel_for.h>

#include "degrade/effect.hpp"
#include "degrade/tree_region.hpp"

namespace angiosynth {
namespace {

// The distance each node's blood has travelled from its tree's inflow (the root), in mm of the
// root segment's flow: with slow flow on, each segment counts length × v_root / v, so the slow
// blood of thin vessels saturates sooner (v = flow / (π r²); Murray's law makes v ∝ r).
std::vector<double> travelledDistance(const VascularTree& t, bool slow_flow) {
  std::vector<double> d(t.nodeCount(), 0.0);
  std::vector<double> v_root(t.nodeCount(), 0.0);
  const auto velocity = [&](std::int32_t s) {
    const double area = M_PI * t.radius[s] * t.radius[s];
    return (s < std::int32_t(t.flow.size()) && area > 0) ? t.flow[s] / area : 0.0;
  };
  std::deque<std::int32_t> queue;
  for (std::int32_t r : t.roots()) queue.push_back(r);
  while (!queue.empty()) {
    const std::int32_t n = queue.front();
    queue.pop_front();
    for (std::int32_t s : {t.child0[n], t.child1[n]}) {
      if (s < 0) continue;
      // The reference velocity is the first segment's of each tree.
      v_root[s] = t.isRoot(n) ? velocity(s) : v_root[n];
      const double v = velocity(s);
      const double weight = slow_flow && v > 0 && v_root[s] > 0 ? v_root[s] / v : 1.0;
      d[s] = d[n] + t.length[s] * weight;
      queue.push_back(s);
    }
  }
  return d;
}

void applyInflow(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const VascularTree& t = *s.tree;
  const double length = p("length"), floor = p("floor");
  const bool slow_flow = p("slow_flow") > 0.5;
  const std::vector<double> node_distance = travelledDistance(t, slow_flow);
  // Each voxel takes the travelled distance of the nearest vessel axis within reach.
  const double reach = 0.87 * std::max({s.grid.spacing_mm.x, s.grid.spacing_mm.y, s.grid.spacing_mm.z});
  Volume<float> nearest(s.grid), travelled(s.grid);
  std::fill(nearest.data.begin(), nearest.data.end(), INFINITY);
  double farthest = 0;
  for (std::int32_t seg = 0; seg < t.nodeCount(); ++seg) {
    if (t.isRoot(seg)) continue;
    const Vec3 a = t.position[t.parent[seg]], b = t.position[seg];
    const double len = t.length[seg];
    const double per_mm = len > 0 ? (node_distance[seg] - node_distance[t.parent[seg]]) / len : 0;
    const double margin = t.maxRadius(seg) + reach;
    farthest = std::max(farthest, node_distance[seg]);
    const VoxelBox box = boxAround(s.grid, a, b, margin);
    if (box.hi[2] < box.lo[2]) continue;
    tbb::parallel_for(box.lo[2], box.hi[2] + 1, [&](std::int64_t k) {
      for (std::int64_t j = box.lo[1]; j <= box.hi[1]; ++j)
        for (std::int64_t i = box.lo[0]; i <= box.hi[0]; ++i) {
          const Vec3 q = s.grid.centre(i, j, k);
          const double along = len > 0 ? std::clamp(dot(q - a, b - a) / len, 0.0, len) : 0.0;
          const Vec3 foot = len > 0 ? a + (b - a) * (along / len) : a;
          const double off = distance(q, foot) - t.maxRadius(seg);  // to the surface, < 0 inside
          if (off > reach) continue;
          const std::int64_t v = s.grid.flat(i, j, k);
          if (off < nearest.data[v]) {
            nearest.data[v] = static_cast<float>(off);
            travelled.data[v] = static_cast<float>(node_distance[t.parent[seg]] + along * per_mm);
          }
        }
    });
  }
  const double contrast = s.vessel - s.background;
  forEachVoxel(s.grid.voxelCount(), [&](std::int64_t v) {
    if (!std::isfinite(nearest.data[v]) || s.fraction->data[v] <= 0) return;
    const double kept = floor + (1 - floor) * std::exp(-travelled.data[v] / length);
    s.image.data[v] -= static_cast<float>((1 - kept) * contrast * s.fraction->data[v]);
  });
  ctx.record["farthest_travel_mm"] = farthest;
  ctx.record["signal_kept_at_farthest"] = floor + (1 - floor) * std::exp(-farthest / length);
}

void applySlab(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const int axis = static_cast<int>(std::llround(p("axis")));
  const double thickness = p("thickness"), drop = p("drop"), edge = p("edge_loss");
  const bool upward = p("inflow_from_low") > 0.5;
  const double contrast = s.vessel - s.background;
  const double extent = s.grid.dims[axis] * s.grid.spacing_mm[axis];
  ctx.record["slabs"] = std::int64_t(std::ceil(extent / thickness - 1e-9));
  forEachVoxelIjk(s.grid, [&](std::int64_t v, std::int64_t i, std::int64_t j, std::int64_t k) {
    const std::int64_t idx[3] = {i, j, k};
    const double x = (idx[axis] + 0.5) * s.grid.spacing_mm[axis];
    double zeta = std::fmod(x, thickness) / thickness;  // 0 at the slab's low face, 1 at its high face
    if (!upward) zeta = 1 - zeta;
    // Blood loses signal across each slab from the face it enters; stationary tissue follows the
    // slab's excitation profile, weakest at both faces.
    const double vessel_gain = 1 - drop * zeta, tissue_gain = 1 - edge * (2 * zeta - 1) * (2 * zeta - 1);
    const double vessel_part = contrast * s.fraction->data[v];
    s.image.data[v] = static_cast<float>((s.image.data[v] - vessel_part) * tissue_gain + vessel_part * vessel_gain);
  });
}

}  // namespace

extern const EffectType kInflow{
    "inflow",
    "TOF inflow saturation: vessel signal falls with the distance its blood travelled from the tree's inflow, "
    "floor + (1 − floor)·exp(−distance/length); with slow_flow the distance of each vessel counts v_root/v times (thin, slow "
    "vessels saturate sooner)",
    {{"length", ParamKind::Length, 1e-9, 1e12, nullptr,
      "travel at the inflow's velocity over which the signal above floor falls by e (velocity × TR / (TR/T1 − ln cos α))"},
     {"floor", ParamKind::Probability, 0, 1, "0", "share of the signal saturated blood keeps (steady state)"},
     {"slow_flow", ParamKind::Count, 0, 1, "1", "1: weight each vessel's length by the inflow's velocity over its own (from the tree's flows)"}},
    applyInflow,
    /*moves_geometry=*/false,
    /*noise=*/false,
    /*working_bytes_per_voxel=*/8};

extern const EffectType kSlab{
    "slab",
    "multi-slab TOF: the field of view acquired in slabs of thickness along axis; blood loses drop of its signal across each slab "
    "from the face it enters and tissue is edge_loss darker at both faces, so intensities step at slab borders (venetian blind)",
    {{"axis", ParamKind::Count, 0, 2, "2", "slab axis: 0 x, 1 y, 2 z"},
     {"thickness", ParamKind::Length, 1e-9, 1e12, nullptr, "slab thickness"},
     {"drop", ParamKind::Probability, 0, 1, "0.3", "share of the vessel signal lost from a slab's inflow face to its far face"},
     {"edge_loss", ParamKind::Probability, 0, 1, "0.1", "share of the tissue signal lost at a slab's faces (its excitation profile)"},
     {"inflow_from_low", ParamKind::Count, 0, 1, "1", "1: blood enters each slab at its low-index face (feet to head)"}},
    applySlab};

}  // namespace angiosynth
