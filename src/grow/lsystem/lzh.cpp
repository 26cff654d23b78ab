#include "grow/lsystem/lzh.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>

namespace angiosynth {

namespace {

// Above this many nodes the network would not fit a sample's memory (≈150 bytes a node).
constexpr std::int64_t kMaxNodes = std::int64_t(6) << 20;

std::string sig6(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}
std::string mm(double v) { return sig6(v) + " mm"; }

double& axis(Vec3& v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }

}  // namespace

double taperedResistance(double viscosity, double l, double a, double b) {
  if (a == b) return 8 * viscosity * l / (std::numbers::pi * a * a * a * a);
  return 8 * viscosity * l / (3 * std::numbers::pi) * (a * a + a * b + b * b) / (a * a * a * b * b * b);
}

LzhPlan planLzh(const LzhParameters& p) {
  const auto positive = [](double v, const char* key) {
    if (!(v > 0) || !std::isfinite(v)) throw LzhError(key, std::string(key) + " must be a positive length");
  };
  positive(p.block_width, "block_width");
  positive(p.height, "block_height");
  positive(p.start_length, "start_length");
  positive(p.capillary_length, "capillary_length");
  positive(p.start_diameter, "start_diameter");
  positive(p.capillary_diameter, "capillary_diameter");
  positive(p.spacing, "capillary_spacing");
  for (const auto& [v, key] : {std::pair{p.start_wall, "start_wall"}, {p.capillary_wall, "capillary_wall"}})
    if (!(v >= 0) || !std::isfinite(v)) throw LzhError(key, std::string(key) + " must be a length ≥ 0");

  LzhPlan plan;
  plan.middle_height = (p.height - 2 * p.start_length - p.capillary_length) / 2;
  if (!(plan.middle_height > 0))
    throw LzhError("block_height", "block_height " + mm(p.height) +
                                       " leaves no room for the trees: it must exceed 2·start_length + capillary_length = " +
                                       mm(2 * p.start_length + p.capillary_length));
  // The capillaries keep half the spacing from the block's sides: they span c = w_b − d.
  plan.leaf_span = p.block_width - p.spacing;
  if (!(plan.leaf_span > 0))
    throw LzhError("capillary_spacing", "capillary_spacing " + mm(p.spacing) + " must be smaller than block_width " + mm(p.block_width));
  const double ratio = plan.leaf_span / p.spacing;
  // 2^N leaves lie c/(2^N − 1) apart: N = ⌈log2(c/d + 1)⌉ keeps that ≤ d (the printed
  // ⌈log2(c/d)⌉ does not, e.g. at c/d = 4).
  const double n_real = p.printed_level_rule ? std::log2(ratio) : std::log2(ratio + 1);
  const double n_ceil = std::ceil(n_real - 1e-12);
  if (n_ceil < 1)
    throw LzhError("level_rule", "the printed rule ⌈log2(c/d)⌉ gives no level for c/d = " + sig6(ratio) +
                                     " ≤ 1; use level_rule = \"corrected\" or a smaller capillary_spacing");
  const int levels_2d = static_cast<int>(std::min(n_ceil, 40.0));
  const int levels = p.dimension == 3 ? 2 * levels_2d : levels_2d;
  const std::int64_t nodes = levels > 30 ? kMaxNodes + 1 : 6 * (std::int64_t(1) << levels);
  if (nodes > kMaxNodes) {
    std::ostringstream o;
    o << "capillary_spacing " << mm(p.spacing) << " needs " << levels << " levels (" << (levels > 30 ? "over 6e9" : std::to_string(nodes))
      << " nodes, about " << (levels > 30 ? std::string("too many") : sig6(double(nodes) * 150 / 1048576) + " MiB") << "); at most " << kMaxNodes
      << " nodes: a larger spacing or a smaller block";
    throw LzhError("capillary_spacing", o.str());
  }
  plan.levels_2d = levels_2d;
  plan.levels = levels;
  plan.nodes = nodes;
  const double two_n = std::ldexp(1.0, levels_2d);
  plan.w = plan.leaf_span * two_n / (two_n - 1);
  for (int n = 0; n < levels_2d; ++n) plan.offset.push_back(plan.w / std::ldexp(1.0, n + 2));
  plan.leaf_spacing = plan.leaf_span / (two_n - 1);
  plan.leaves = std::int64_t(1) << levels;
  // 3D: each plane's tree descends h_m over 2N levels, i.e. a 2D tree of height h_m/2 per plane.
  plan.theta = std::atan(p.dimension == 3 ? plan.leaf_span / plan.middle_height : plan.leaf_span / (2 * plan.middle_height));
  for (int n = 0; n < levels; ++n) plan.length.push_back(plan.offset[std::size_t(p.dimension == 3 ? n / 2 : n)] / std::sin(plan.theta));
  const double outer_c = p.capillary_diameter + 2 * p.capillary_wall;
  if (plan.leaf_spacing < outer_c)
    throw LzhError("capillary_spacing", "neighbouring capillaries lie " + mm(plan.leaf_spacing) + " apart, less than their outer diameter " +
                                            mm(outer_c) + " (capillary_diameter + 2·capillary_wall): their walls would overlap");
  return plan;
}

Forest buildLzhNetwork(const LzhParameters& p, const LzhPlan& plan, const Vec3& corner, double plane_z) {
  const int up = p.dimension == 3 ? 2 : 1;  // the vertical axis
  const auto lateral = [&](int level) { return p.dimension == 3 && level % 2 == 1 ? 1 : 0; };
  const double cos_t = std::cos(plan.theta);
  Vec3 top = corner;
  top.x += p.block_width / 2;
  if (p.dimension == 3)
    top.y += p.block_width / 2;
  else
    top.z = plane_z;
  axis(top, up) += p.height;
  const double mid = corner[up] + p.height / 2;  // the mirror plane

  // The arterial tree, breadth first: inlet top, the middle tree's root, then each level.
  VascularTree art;
  art.reserve(std::size_t(2 * plan.leaves));
  std::vector<double> path;  // path length from the inlet to each node
  art.addNode(top, -1, 0);
  path.push_back(0);
  Vec3 root = top;
  axis(root, up) -= p.start_length;
  art.addNode(root, 0);
  path.push_back(p.start_length);
  std::vector<std::int32_t> front{1}, next;
  for (int n = 0; n < plan.levels; ++n) {
    const double lw = plan.offset[std::size_t(p.dimension == 3 ? n / 2 : n)], drop = plan.length[std::size_t(n)] * cos_t;
    next.clear();
    for (auto i : front)
      for (double side : {-1.0, 1.0}) {
        Vec3 q = art.position[std::size_t(i)];
        axis(q, lateral(n)) += side * lw;
        axis(q, up) -= drop;
        next.push_back(art.addNode(q, i));
        path.push_back(path[std::size_t(i)] + plan.length[std::size_t(n)]);
      }
    front.swap(next);
  }
  const std::vector<std::int32_t> leaves = front;
  // Diameter and wall: linear in the path length, d_s at the inlet, d_c at the capillaries.
  const double total = path[std::size_t(leaves.front())];
  const auto lerp = [&](std::int32_t i, double a, double b) { return a + (b - a) * (path[std::size_t(i)] / total); };
  for (std::int32_t i = 1; i < art.nodeCount(); ++i) {
    const auto pa = art.parent[std::size_t(i)];
    art.radius_start[i] = lerp(pa, p.start_diameter, p.capillary_diameter) / 2;
    art.radius[i] = lerp(i, p.start_diameter, p.capillary_diameter) / 2;
    art.wall_start[i] = lerp(pa, p.start_wall, p.capillary_wall);
    art.wall[i] = lerp(i, p.start_wall, p.capillary_wall);
  }
  // The venous tree: the arterial one mirrored through the mid-plane, node for node.
  VascularTree ven;
  ven.reserve(std::size_t(art.nodeCount()));
  for (std::int32_t i = 0; i < art.nodeCount(); ++i) {
    Vec3 q = art.position[std::size_t(i)];
    axis(q, up) = 2 * mid - q[up];
    ven.addNode(q, art.parent[std::size_t(i)], 0);
    if (i > 0) {
      ven.radius_start[i] = art.radius_start[i];
      ven.radius[i] = art.radius[i];
      ven.wall_start[i] = art.wall_start[i];
      ven.wall[i] = art.wall[i];
    }
  }

  // Flows: each capillary carries Q/K; a vessel the capillaries below it. Pressures fall from
  // the inlet through the arteries and capillaries, then on through the veins to the outlet.
  const double q_cap = p.perfusion_flow / double(leaves.size());
  const auto flows = [&](VascularTree& t) {
    for (std::int32_t i = t.nodeCount() - 1; i >= 1; --i) {
      const bool leaf = t.child0[std::size_t(i)] < 0;
      t.terminals[i] = leaf ? 1 : t.terminals[t.child0[i]] + (t.child1[i] >= 0 ? t.terminals[t.child1[i]] : 0);
      t.flow[i] = q_cap * t.terminals[i];
    }
    t.terminals[0] = t.terminals[1];
  };
  flows(art);
  flows(ven);
  const auto drop = [&](const VascularTree& t, std::int32_t i) {
    return t.flow[i] * taperedResistance(p.viscosity, t.length[i], t.startRadius(i), t.radius[i]);
  };
  art.pressure[0] = p.perfusion_pressure;
  for (std::int32_t i = 1; i < art.nodeCount(); ++i) art.pressure[i] = art.pressure[art.parent[i]] - drop(art, i);
  const double r_cap = p.capillary_diameter / 2;
  const double cap_drop = q_cap * taperedResistance(p.viscosity, p.capillary_length, r_cap, r_cap);
  for (auto a : leaves) ven.pressure[a] = art.pressure[a] - cap_drop;
  // Veins drain toward their root, the outlet: a node's pressure is its child's less the drop
  // along that child's vessel (both children give the same by symmetry; children have larger ids).
  for (std::int32_t i = ven.nodeCount() - 1; i >= 1; --i)
    if (ven.child0[std::size_t(i)] >= 0) ven.pressure[i] = ven.pressure[ven.child0[i]] - drop(ven, ven.child0[i]);
  ven.pressure[0] = ven.pressure[1] - drop(ven, 1);

  Forest f;
  f.vessels.reserve(std::size_t(plan.nodes));
  f.vessels.appendTree(art, 0);
  f.trees.push_back({"inlet", "artery", 0});
  // Capillaries, each its own tree: from an arterial leaf straight down to the venous leaf
  // (the leaf's mirror image, so the two trees meet exactly).
  auto& t = f.vessels;
  for (std::size_t k = 0; k < leaves.size(); ++k) {
    const auto a = leaves[k];
    const auto top = t.addNode(art.position[std::size_t(a)], -1, std::int32_t(f.trees.size()));
    const auto end = t.addNode(ven.position[std::size_t(a)], top);
    t.radius[end] = r_cap;
    t.wall_start[end] = t.wall[end] = p.capillary_wall;
    t.flow[end] = q_cap;
    t.pressure[top] = art.pressure[a];
    t.pressure[end] = ven.pressure[a];
    f.trees.push_back({"capillary_" + std::to_string(k + 1), "capillary", 0});
  }
  f.vessels.appendTree(ven, std::int32_t(f.trees.size()));
  f.trees.push_back({"outlet", "vein", 0});
  assignClassLabels(f.trees);
  return f;
}

}  // namespace angiosynth
