// Method "lsystem": its parameters, TOML reader, description and grow function.
#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "core/quantity_json.hpp"
#include "grow/common/intersections.hpp"
#include "grow/common/method_tables.hpp"
#include "grow/common/region_tables.hpp"
#include "grow/lsystem/setup.hpp"
#include "io/param_checks.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

// The block and its vessels with room around them: vessels are rasterised unclipped.
double marginMm(const LsystemSetup& s) {
  const auto& p = s.lzh;
  return std::max(p.start_diameter / 2 + p.start_wall, p.capillary_diameter / 2 + p.capillary_wall) + 2 * s.voxel_mm;
}

class PreparedLsystem final : public PreparedGrowth {
 public:
  explicit PreparedLsystem(const LsystemSetup& s) : setup_(s) {
    const auto& p = s.lzh;
    const double m = marginMm(s);
    frame_.voxel_mm = s.voxel_mm;
    const auto voxels = [&](double mm) { return std::int32_t(std::ceil((mm + 2 * m) / s.voxel_mm - 1e-9)); };
    frame_.dims = {voxels(p.block_width), p.dimension == 3 ? voxels(p.block_width) : voxels(p.height), p.dimension == 3 ? voxels(p.height) : 1};
    corner_ = Vec3(m, m, p.dimension == 3 ? m : s.voxel_mm / 2);
  }
  const DemandMap& frame() const override { return frame_; }
  void checkFeasibility() const override {}  // the plan was solved and checked when the file was read
  Forest grow(std::uint64_t, std::uint64_t, GrowthReport& report, const ProgressFn& progress) const override {
    Forest f = buildLzhNetwork(setup_.lzh, setup_.plan, corner_, corner_.z);
    // Overlaps within the arterial and the venous tree, each vessel as a capsule of its larger
    // radius; capillaries keep their spacing by construction (checked when the file was read).
    report.intersecting_pairs = 0;
    const auto roots = f.vessels.roots();
    for (std::size_t k : {std::size_t(0), roots.size() - 1}) {
      VascularTree t;
      const auto begin = roots[k], end = k + 1 < roots.size() ? roots[k + 1] : f.vessels.nodeCount();
      for (auto i = begin; i < end; ++i) {
        t.addNode(f.vessels.position[i], f.vessels.parent[i] >= 0 ? f.vessels.parent[i] - begin : -1);
        t.radius[i - begin] = f.vessels.maxRadius(i);
      }
      const Vec3 hi = Vec3(frame_.dims[0], frame_.dims[1], frame_.dims[2]) * frame_.voxel_mm;
      report.intersecting_pairs += std::int64_t(intersectingPairs(t, Vec3(0, 0, 0), hi).size());
    }
    report.root_radius_mm = setup_.lzh.start_diameter / 2;
    if (progress) progress(1, 1);
    return f;
  }
  void addStatistics(const GrowthReport&, Json& stats) const override {
    const auto& plan = setup_.plan;
    stats["levels"] = plan.levels;
    stats["levels_per_plane"] = plan.levels_2d;
    stats["theta"] = quantityJson(plan.theta * 180 / std::numbers::pi, "deg");
    stats["capillaries"] = plan.leaves;
    stats["capillary_grid"] = setup_.lzh.dimension == 3 ? Json::array({std::int64_t(1) << plan.levels_2d, std::int64_t(1) << plan.levels_2d})
                                                         : Json::array({std::int64_t(1) << plan.levels_2d});
    stats["capillary_pitch"] = quantityJson(plan.leaf_spacing, "mm");
    stats["capillary_span"] = quantityJson(plan.leaf_span, "mm");
    stats["middle_tree_height"] = quantityJson(plan.middle_height, "mm");
    stats["level_lengths"] = Json{{"value", plan.length}, {"unit", "mm"}};
    stats["level_offsets"] = Json{{"value", plan.offset}, {"unit", "mm"}};
    stats["segments_per_path"] = 3 + 2 * plan.levels;
    stats["nodes_per_path"] = 4 + 2 * plan.levels;
  }

 private:
  const LsystemSetup& setup_;
  DemandMap frame_;
  Vec3 corner_;
};

std::shared_ptr<const GrowthSetup> readLsystemToml(const TomlReader& r, const GrowthMethod& m) {
  auto s = std::make_shared<LsystemSetup>();
  s->parameter_file = r.file();
  const auto& dom = methodTable(r, m, "domain");
  const auto& tree = methodTable(r, m, "tree");
  const auto& ph = methodTable(r, m, "physics");
  s->voxel_mm = r.quantity(dom, "domain", "voxel_size", Dimension::Length);
  checkRange(s->voxel_mm, Limits::kMinVoxel, false, Limits::kMaxVoxel, false, r.at(dom, "voxel_size"), "voxel_size (mm)");
  choice<std::string>(r, tree, "tree", "mode", "lzh", {{"lzh", "lzh"}});
  auto& p = s->lzh;
  p.dimension = declaredCount(r, m, tree, "tree", "dimension", 2, 3);
  const auto length = [&](const char* key) {
    const double v = declaredQuantity(r, m, tree, "tree", key, Dimension::Length, s->voxel_mm);
    checkRange(v, 0, true, Limits::kMaxLength, false, r.at(tree, key), std::string(key) + " (mm)");
    return v;
  };
  p.block_width = length("block_width");
  p.height = length("block_height");
  p.start_length = length("start_length");
  p.capillary_length = length("capillary_length");
  p.start_diameter = length("start_diameter");
  p.capillary_diameter = length("capillary_diameter");
  p.spacing = length("capillary_spacing");
  for (const char* key : {"start_wall", "capillary_wall"}) {
    const double v = declaredQuantity(r, m, tree, "tree", key, Dimension::Length, s->voxel_mm);
    checkRange(v, 0, false, Limits::kMaxLength, false, r.at(tree, key), std::string(key) + " (mm)");
    (std::string(key) == "start_wall" ? p.start_wall : p.capillary_wall) = v;
  }
  p.printed_level_rule = choice<bool>(r, tree, "tree", "level_rule", false, {{"corrected", false}, {"printed", true}});
  auto& phys = s->physics_summary;
  phys.viscosity = declaredQuantity(r, m, ph, "physics", "viscosity", Dimension::Viscosity);
  checkRange(phys.viscosity, Limits::kMinViscosity, false, Limits::kMaxViscosity, false, r.at(ph, "viscosity"), "viscosity (Pa*s)");
  phys.perfusion_pressure = declaredQuantity(r, m, ph, "physics", "perfusion_pressure", Dimension::Pressure);
  checkRange(phys.perfusion_pressure, 0, false, Limits::kMaxPressure, false, r.at(ph, "perfusion_pressure"), "perfusion_pressure (Pa)");
  phys.perfusion_flow = declaredQuantity(r, m, ph, "physics", "perfusion_flow", Dimension::Flow);
  checkRange(phys.perfusion_flow, Limits::kMinFlow, false, Limits::kMaxFlow, false, r.at(ph, "perfusion_flow"), "perfusion_flow (mm^3/s)");
  p.viscosity = phys.viscosity;
  p.perfusion_pressure = phys.perfusion_pressure;
  p.perfusion_flow = phys.perfusion_flow;
  try {
    s->plan = planLzh(p);
  } catch (const LzhError& e) {
    throw InputError(r.file(), tree.get(e.key) ? r.lineOf(tree.get(e.key)) : r.lineOf(&tree), e.what());
  }
  phys.total_terminals = s->plan.leaves;
  // The outlet's pressure follows from the inflow and the resistances (checked non-negative).
  const Forest f = buildLzhNetwork(p, s->plan, Vec3(0, 0, 0));
  phys.terminal_pressure = f.vessels.pressure[f.vessels.roots().back()];
  if (!(phys.terminal_pressure >= 0))
    throw InputError(r.file(), r.lineOf(ph.get("perfusion_flow") ? ph.get("perfusion_flow") : &ph),
                     "perfusion_flow " + std::to_string(phys.perfusion_flow) + " mm^3/s needs more than the inlet's perfusion_pressure (" +
                         std::to_string(phys.perfusion_pressure) + " Pa) to pass the network: the outlet would be at " +
                         std::to_string(phys.terminal_pressure) + " Pa; lower the flow or widen the vessels");
  return s;
}

}  // namespace

Json LsystemSetup::describe() const {
  const auto& p = lzh;
  Json j;
  j["method"] = "lsystem";
  j["mode"] = "lzh";
  j["dimension"] = p.dimension;
  j["voxel_size"] = quantityJson(voxel_mm, "mm");
  j["block_width"] = quantityJson(p.block_width, "mm");
  j["block_height"] = quantityJson(p.height, "mm");
  j["start_length"] = quantityJson(p.start_length, "mm");
  j["capillary_length"] = quantityJson(p.capillary_length, "mm");
  j["start_diameter"] = quantityJson(p.start_diameter, "mm");
  j["capillary_diameter"] = quantityJson(p.capillary_diameter, "mm");
  j["start_wall"] = quantityJson(p.start_wall, "mm");
  j["capillary_wall"] = quantityJson(p.capillary_wall, "mm");
  j["capillary_spacing"] = quantityJson(p.spacing, "mm");
  j["level_rule"] = p.printed_level_rule ? "printed: N = ceil(log2(c/d))" : "corrected: N = ceil(log2(c/d + 1))";
  j["viscosity"] = quantityJson(physics_summary.viscosity, "Pa*s");
  j["perfusion_pressure"] = quantityJson(physics_summary.perfusion_pressure, "Pa");
  j["perfusion_flow"] = quantityJson(physics_summary.perfusion_flow, "mm^3/s");
  j["outlet_pressure"] = quantityJson(physics_summary.terminal_pressure, "Pa");
  return j;
}

std::unique_ptr<PreparedGrowth> LsystemSetup::prepare(std::uint64_t) const { return std::make_unique<PreparedLsystem>(*this); }

const GrowthMethod kLsystemMethod{
    "lsystem",
    "L-system vessel networks. Mode lzh (Lázaro 2011; seed 004): a printable closed network from high-level parameters "
    "(block, start and capillary vessels, capillary spacing) inverted into levels N, angle θ and lengths L_n; a 3D turtle "
    "with a 90° roll per level; the venous half mirrored through the block's mid-plane and joined by vertical capillaries; "
    "diameter and wall thickness linear in path length (tapered vessels)",
    {
        {"domain", "voxel_size", "mm", nullptr, "the image voxel edge (the frame is the block with room for the vessels)"},
        {"tree", "mode", "text", "lzh", "lzh: seed 004's inverse problem"},
        {"tree", "dimension", "count", "3", "2: one plane (2^N capillaries in a row); 3: levels alternate between two planes (a 2^N × 2^N capillary grid)"},
        {"tree", "block_width", "mm", nullptr, "w_b, the block's width (3D: w_b × w_b × h)"},
        {"tree", "block_height", "mm", nullptr, "h, from the inlet's top to the outlet's bottom"},
        {"tree", "start_length", "mm", nullptr, "L_s, the vertical inlet (and outlet) vessel"},
        {"tree", "capillary_length", "mm", nullptr, "L_c, the vertical capillaries"},
        {"tree", "start_diameter", "mm", nullptr, "d_s, the lumen at the inlet"},
        {"tree", "capillary_diameter", "mm", nullptr, "d_c, the lumen of the capillaries"},
        {"tree", "start_wall", "mm", "0 mm", "t_ws, the wall thickness at the inlet"},
        {"tree", "capillary_wall", "mm", "0 mm", "t_wc, the wall thickness of the capillaries"},
        {"tree", "capillary_spacing", "mm", nullptr, "d, the largest distance between neighbouring capillaries (and twice their distance from the block's sides)"},
        {"tree", "level_rule", "text", "corrected", "corrected: N = ⌈log2(c/d + 1)⌉, so capillaries lie at most d apart; printed: the thesis's ⌈log2(c/d)⌉ (farther apart than d when c/d is a power of 2)"},
        {"physics", "viscosity", "Pa*s", "0.0036 Pa*s", "blood viscosity η (flows and pressures of the outputs)"},
        {"physics", "perfusion_pressure", "Pa", "100 mmHg", "pressure at the inlet"},
        {"physics", "perfusion_flow", "mm^3/s", "1 mL/min", "Q into the inlet, the same through every capillary; the outlet's pressure follows (Poiseuille, tapered vessels)"},
    },
    &readLsystemToml};

}  // namespace angiosynth
