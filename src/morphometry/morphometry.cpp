#include "morphometry/morphometry.hpp"

#include "core/format.hpp"
#include "core/point_hash.hpp"
#include "core/polyline_turns.hpp"
#include "core/quantity_json.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numeric>
#include <sstream>

namespace angiosynth {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDeg = 180.0 / M_PI;

double angleBetween(const Vec3& a, const Vec3& b) {
  const double na = norm(a), nb = norm(b);
  if (!(na > 0) || !(nb > 0)) return kNaN;
  return std::acos(std::clamp(dot(a, b) / (na * nb), -1.0, 1.0));
}

// Tortuosity of a polyline (Bullitt et al. 2003): inflections and the sum of angles.
void tortuosity(const std::vector<Vec3>& p, VesselMeasures& v) {
  const PolylineTurns turns = polylineTurns(p);
  v.inflections = turns.inflections;
  v.sum_of_angles_per_mm = v.length_mm > 0 ? turns.total_angle / v.length_mm : 0;
}

double quantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return kNaN;
  const double at = q * double(sorted.size() - 1);
  const std::size_t lo = std::size_t(std::floor(at));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (at - double(lo)) * (sorted[hi] - sorted[lo]);
}

}  // namespace

double leastSquaresSlope(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = double(x.size());
  if (x.size() < 2) return kNaN;
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n, my = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
  return sxx > 0 ? sxy / sxx : kNaN;
}

namespace {

// γ minimising Σ (x1^γ + x2^γ − 1)²: a scan on [0.5, 20], then golden-section refinement.
double fittedMurray(const std::vector<std::pair<double, double>>& x) {
  if (x.empty()) return kNaN;
  const auto cost = [&](double g) {
    double s = 0;
    for (const auto& [a, b] : x) {
      const double r = std::pow(a, g) + std::pow(b, g) - 1;
      s += r * r;
    }
    return s;
  };
  double best = 0.5, best_cost = cost(0.5);
  for (double g = 0.55; g <= 20.0 + 1e-9; g += 0.05)
    if (const double c = cost(g); c < best_cost) best = g, best_cost = c;
  double lo = std::max(0.5, best - 0.05), hi = std::min(20.0, best + 0.05);
  const double phi = (std::sqrt(5.0) - 1) / 2;
  for (int it = 0; it < 60; ++it) {
    const double a = hi - phi * (hi - lo), b = lo + phi * (hi - lo);
    if (cost(a) < cost(b))
      hi = b;
    else
      lo = a;
  }
  return (lo + hi) / 2;
}

// Mean distance from each point to its nearest other point.
double meanNearestNeighbour(const std::vector<Vec3>& p) {
  if (p.size() < 2) return kNaN;
  Vec3 lo = p[0], hi = p[0];
  for (const auto& q : p) lo = componentMin(lo, q), hi = componentMax(hi, q);
  // Cells from the largest extent, so that points on a plane or a line still spread over them.
  const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 1e-9});
  PointHash grid(lo, hi, extent / std::max(1.0, std::cbrt(double(p.size()))), false);
  for (std::size_t n = 0; n < p.size(); ++n) grid.insert(p[n], std::int32_t(n));
  const double reach = 2 * extent;  // beyond the box's diagonal: every point is a candidate
  double total = 0;
  for (std::size_t n = 0; n < p.size(); ++n) {
    const auto nearest = grid.nearest(p[n], reach, [&](std::int32_t id) {
      return std::size_t(id) == n ? std::numeric_limits<double>::infinity() : dot(p[std::size_t(id)] - p[n], p[std::size_t(id)] - p[n]);
    });
    total += distance(p[n], p[std::size_t(nearest)]);
  }
  return total / double(p.size());
}

// Each value as the shortest text that reads back to the same double.
std::string number(double v) { return std::isfinite(v) ? exactNumber(v) : std::string(); }

}  // namespace

Summary summarise(std::vector<double> values) {
  values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }), values.end());
  Summary s;
  s.count = std::int64_t(values.size());
  if (values.empty()) {
    s.mean = s.sd = s.min = s.p05 = s.p25 = s.median = s.p75 = s.p95 = s.max = kNaN;
    return s;
  }
  std::sort(values.begin(), values.end());
  s.mean = std::accumulate(values.begin(), values.end(), 0.0) / double(values.size());
  double ss = 0;
  for (double v : values) ss += (v - s.mean) * (v - s.mean);
  s.sd = values.size() > 1 ? std::sqrt(ss / double(values.size() - 1)) : 0;
  s.min = values.front();
  s.max = values.back();
  s.p05 = quantile(values, 0.05);
  s.p25 = quantile(values, 0.25);
  s.median = quantile(values, 0.5);
  s.p75 = quantile(values, 0.75);
  s.p95 = quantile(values, 0.95);
  return s;
}

const std::vector<std::pair<std::string, double (*)(const VesselMeasures&)>>& vesselStatistics() {
  using V = VesselMeasures;
  static const std::vector<std::pair<std::string, double (*)(const V&)>> list{
      {"radius_mm", [](const V& v) { return v.radius_mm; }},
      {"length_mm", [](const V& v) { return v.length_mm; }},
      {"length_over_radius", [](const V& v) { return v.length_over_radius; }},
      {"distance_metric", [](const V& v) { return v.distance_metric; }},
      {"inflections", [](const V& v) { return double(v.inflections); }},
      {"sum_of_angles_per_mm", [](const V& v) { return v.sum_of_angles_per_mm; }},
      {"generation", [](const V& v) { return double(v.generation); }},
      {"strahler", [](const V& v) { return double(v.strahler); }}};
  return list;
}

const std::vector<std::pair<std::string, double (*)(const BifurcationMeasures&)>>& bifurcationStatistics() {
  using B = BifurcationMeasures;
  static const std::vector<std::pair<std::string, double (*)(const B&)>> list{
      {"angle_large_deg", [](const B& b) { return b.angle_large_deg; }},
      {"angle_small_deg", [](const B& b) { return b.angle_small_deg; }},
      {"angle_between_deg", [](const B& b) { return b.angle_between_deg; }},
      {"out_of_plane_deg", [](const B& b) { return b.out_of_plane_deg; }},
      {"asymmetry", [](const B& b) { return b.asymmetry; }},
      {"area_ratio", [](const B& b) { return b.area_ratio; }},
      {"daughter_area_ratio", [](const B& b) { return b.daughter_area_ratio; }},
      {"murray_exponent", [](const B& b) { return b.murray_exponent; }}};
  return list;
}

double murrayExponent(double r0, double r1, double r2) {
  if (!(r0 > 0) || !(r1 > 0) || !(r2 > 0) || r1 >= r0 || r2 >= r0) return kNaN;
  const double x1 = r1 / r0, x2 = r2 / r0;
  // x1^γ + x2^γ − 1 falls from 1 at γ = 0 towards −1: one root.
  double lo = 0, hi = 1;
  while (std::pow(x1, hi) + std::pow(x2, hi) > 1 && hi < 1e6) hi *= 2;
  for (int it = 0; it < 200 && hi - lo > 1e-12 * hi; ++it) {
    const double mid = (lo + hi) / 2;
    (std::pow(x1, mid) + std::pow(x2, mid) > 1 ? lo : hi) = mid;
  }
  return (lo + hi) / 2;
}

namespace {

// Elements (runs of vessels of one order, joined end to end: from where the order begins, on
// through the child of the same order, the wider when both are) and Horton's ratios from the
// least-squares lines through their log count, mean length and length-weighted mean diameter.
struct OrderTable {
  std::vector<StrahlerOrder> orders;
  HortonRatios horton;
};

OrderTable orderTable(const Morphometry& m, const std::vector<std::vector<std::int32_t>>& children, const std::function<bool(std::int32_t)>& in,
                      const std::vector<int>& order) {
  std::map<int, StrahlerOrder> orders;
  for (std::size_t k = 0; k < m.vessels.size(); ++k) {
    const auto& v = m.vessels[k];
    if (!in(v.tree)) continue;
    auto& o = orders[order[k]];
    o.order = order[k];
    ++o.vessels;
    if (v.parent >= 0 && order[std::size_t(v.parent)] == order[k]) continue;
    double length = 0, diameter_length = 0;
    for (std::int32_t e = std::int32_t(k); e >= 0;) {
      const auto& ve = m.vessels[std::size_t(e)];
      length += ve.length_mm;
      diameter_length += 2 * ve.radius_mm * ve.length_mm;
      std::int32_t next = -1;
      for (const auto c : children[std::size_t(e)])
        if (order[std::size_t(c)] == order[k] && (next < 0 || m.vessels[std::size_t(c)].radius_mm > m.vessels[std::size_t(next)].radius_mm)) next = c;
      e = next;
    }
    ++o.elements;
    o.mean_element_length_mm += length;
    o.mean_element_diameter_mm += length > 0 ? diameter_length / length : 0;
  }
  OrderTable table;
  std::vector<double> order_x, log_n, log_l, log_d;
  for (auto& [k, o] : orders) {
    if (o.elements > 0) {
      o.mean_element_length_mm /= double(o.elements);
      o.mean_element_diameter_mm /= double(o.elements);
      order_x.push_back(k);
      log_n.push_back(std::log(double(o.elements)));
      log_l.push_back(std::log(o.mean_element_length_mm));
      log_d.push_back(std::log(o.mean_element_diameter_mm));
    }
    table.orders.push_back(o);
  }
  table.horton.branching = std::exp(-leastSquaresSlope(order_x, log_n));
  table.horton.length = std::exp(leastSquaresSlope(order_x, log_l));
  table.horton.diameter = std::exp(leastSquaresSlope(order_x, log_d));
  return table;
}

// Diameter-defined Strahler orders (Kassab et al. 1993; Jiang et al. 1994): from the topological
// orders, each vessel moves to the order whose diameter range holds its diameter, a range bounded
// halfway between the neighbouring orders' mean + SD and mean − SD, until fewer than 1 % move.
std::vector<int> diameterDefinedOrders(const Morphometry& m, const std::function<bool(std::int32_t)>& in, std::vector<int> order) {
  // The orders stay those the topology gave; one left empty keeps its last mean and SD.
  std::map<int, std::pair<double, double>> stats;
  for (int round = 0; round < 50; ++round) {
    std::map<int, std::vector<double>> diameters;
    for (std::size_t k = 0; k < m.vessels.size(); ++k)
      if (in(m.vessels[k].tree)) diameters[order[k]].push_back(2 * m.vessels[k].radius_mm);
    for (auto& [k, d] : diameters) {
      const Summary s = summarise(d);
      stats[k] = {s.mean, s.sd};
    }
    if (stats.size() < 2) return order;
    std::vector<int> ids;
    std::vector<double> upper;  // of each order but the last: halfway between its mean + SD and the next's mean − SD
    for (auto it = stats.begin(); it != stats.end(); ++it) {
      ids.push_back(it->first);
      const auto next = std::next(it);
      if (next == stats.end()) break;
      const double u = 0.5 * ((it->second.first + it->second.second) + (next->second.first - next->second.second));
      upper.push_back(upper.empty() ? u : std::max(u, upper.back()));
    }
    std::int64_t moved = 0, counted = 0;
    for (std::size_t k = 0; k < m.vessels.size(); ++k) {
      if (!in(m.vessels[k].tree)) continue;
      const double d = 2 * m.vessels[k].radius_mm;
      std::size_t j = 0;
      while (j < upper.size() && d >= upper[j]) ++j;
      ++counted;
      moved += order[k] != ids[j];
      order[k] = ids[j];
    }
    if (double(moved) < 0.01 * double(counted)) break;
  }
  return order;
}

}  // namespace

Morphometry measureTrees(const VascularTree& t, const std::vector<std::string>& tree_names, const std::vector<std::string>& tree_kinds,
                         const MorphometryOptions& options) {
  Morphometry m;
  const std::int32_t n = t.nodeCount();
  // The segments leaving each branching point, links followed; a link's own node has none.
  std::vector<std::vector<std::int32_t>> kids(static_cast<std::size_t>(n));
  for (std::int32_t i = 0; i < n; ++i)
    if (t.isRoot(i) || !t.isLink(i)) t.junctionChildren(i, kids[std::size_t(i)]);
  std::vector<std::int32_t> vessel_ending_at(static_cast<std::size_t>(n), -1), first_segment;
  // Vessels breadth-first from each root: every vessel after the one it leaves.
  std::vector<std::pair<std::int32_t, std::int32_t>> queue;  // (first segment, parent vessel)
  for (const auto root : t.roots())
    for (const auto s : kids[std::size_t(root)]) queue.emplace_back(s, -1);
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const std::int32_t first = queue[q].first, parent = queue[q].second;
    VesselMeasures v;
    v.parent = parent;
    if (parent >= 0) {
      v.proximal_node = m.vessels[std::size_t(parent)].id;
    } else {
      v.proximal_node = t.parent[std::size_t(first)];
      while (!t.isRoot(v.proximal_node) && t.isLink(v.proximal_node)) v.proximal_node = t.parent[std::size_t(v.proximal_node)];
    }
    v.tree = t.tree.empty() ? 0 : t.tree[std::size_t(first)];
    std::vector<Vec3> points{t.position[std::size_t(v.proximal_node)]};
    double weighted_radius = 0;
    std::int32_t s = first;
    for (;;) {
      const double piece = distance(t.position[std::size_t(s)], points.back());
      points.push_back(t.position[std::size_t(s)]);
      v.length_mm += piece;
      weighted_radius += piece * (t.startRadius(s) + t.radius[std::size_t(s)]) / 2;
      ++v.pieces;
      if (kids[std::size_t(s)].size() != 1) break;
      s = kids[std::size_t(s)][0];
    }
    v.id = s;
    v.terminal = kids[std::size_t(s)].empty();
    v.chord_mm = distance(points.front(), points.back());
    v.radius_mm = v.length_mm > 0 ? weighted_radius / v.length_mm : t.radius[std::size_t(s)];
    v.length_over_radius = v.radius_mm > 0 ? v.length_mm / v.radius_mm : kNaN;
    v.distance_metric = v.chord_mm > 0 ? v.length_mm / v.chord_mm : kNaN;
    tortuosity(points, v);
    if (parent >= 0) {
      const auto& p = m.vessels[std::size_t(parent)];
      v.path_length_to_root_mm = p.path_length_to_root_mm + p.length_mm;
      v.generation = p.generation + 1;
    }
    const auto index = std::int32_t(m.vessels.size());
    vessel_ending_at[std::size_t(s)] = index;
    first_segment.push_back(first);
    m.vessels.push_back(v);
    for (const auto c : kids[std::size_t(s)]) queue.emplace_back(c, index);
  }
  // Children of each vessel, Strahler orders from the terminals up.
  std::vector<std::vector<std::int32_t>> children(m.vessels.size());
  for (std::size_t k = 0; k < m.vessels.size(); ++k)
    if (m.vessels[k].parent >= 0) children[std::size_t(m.vessels[k].parent)].push_back(std::int32_t(k));
  for (std::size_t k = m.vessels.size(); k-- > 0;) {
    auto& v = m.vessels[k];
    if (children[k].empty()) continue;
    int top = 0, at_top = 0;
    for (const auto c : children[k]) {
      const int o = m.vessels[std::size_t(c)].strahler;
      if (o > top)
        top = o, at_top = 1;
      else if (o == top)
        ++at_top;
    }
    v.strahler = at_top >= 2 ? top + 1 : top;
  }
  // Bifurcations: the direction of each vessel at the branching point (its last or first piece).
  const auto lastDirection = [&](const VesselMeasures& v) {
    const std::int32_t before = t.parent[std::size_t(v.id)];
    return t.position[std::size_t(v.id)] - t.position[std::size_t(before)];
  };
  for (std::size_t k = 0; k < m.vessels.size(); ++k) {
    const auto& c = children[k];
    if (c.size() != 2) continue;
    const auto& p = m.vessels[k];
    BifurcationMeasures b;
    b.node = p.id;
    b.tree = p.tree;
    b.parent = std::int32_t(k);
    const std::int32_t f0 = first_segment[std::size_t(c[0])], f1 = first_segment[std::size_t(c[1])];
    const double r0 = t.startRadius(f0), r1 = t.startRadius(f1);
    const bool first_large = r0 > r1 || (r0 == r1 && c[0] < c[1]);
    b.daughter_large = first_large ? c[0] : c[1];
    b.daughter_small = first_large ? c[1] : c[0];
    const std::int32_t fl = first_large ? f0 : f1, fs = first_large ? f1 : f0;
    b.r_parent_mm = t.radius[std::size_t(p.id)];
    b.r_large_mm = t.startRadius(fl);
    b.r_small_mm = t.startRadius(fs);
    const Vec3 u0 = lastDirection(p), ul = t.position[std::size_t(fl)] - t.position[std::size_t(p.id)],
               us = t.position[std::size_t(fs)] - t.position[std::size_t(p.id)];
    b.angle_large_deg = angleBetween(u0, ul) * kDeg;
    b.angle_small_deg = angleBetween(u0, us) * kDeg;
    b.angle_between_deg = angleBetween(ul, us) * kDeg;
    const Vec3 normal = cross(unit(ul), unit(us));
    b.out_of_plane_deg = norm(normal) > 1e-12 ? std::asin(std::clamp(std::abs(dot(unit(u0), unit(normal))), 0.0, 1.0)) * kDeg : kNaN;
    b.asymmetry = b.r_large_mm > 0 ? b.r_small_mm / b.r_large_mm : kNaN;
    b.area_ratio = b.r_parent_mm > 0 ? (b.r_large_mm * b.r_large_mm + b.r_small_mm * b.r_small_mm) / (b.r_parent_mm * b.r_parent_mm) : kNaN;
    b.daughter_area_ratio = b.asymmetry * b.asymmetry;
    b.murray_exponent = murrayExponent(b.r_parent_mm, b.r_large_mm, b.r_small_mm);
    m.bifurcations.push_back(b);
  }
  // Groups: all vessels, each kind (when there are two or more), each tree (when two or more).
  const auto kindOf = [&](std::int32_t tree) {
    return std::size_t(tree) < tree_kinds.size() && !tree_kinds[std::size_t(tree)].empty() ? tree_kinds[std::size_t(tree)] : std::string("tree");
  };
  for (const auto root : t.roots()) {
    const std::int32_t tree = t.tree.empty() ? 0 : t.tree[std::size_t(root)];
    if (std::size_t(tree) >= m.tree_kinds.size()) m.tree_kinds.resize(std::size_t(tree) + 1, "tree");
    m.tree_kinds[std::size_t(tree)] = kindOf(tree);
  }
  const auto nameOf = [&](std::int32_t tree) {
    return std::size_t(tree) < tree_names.size() && !tree_names[std::size_t(tree)].empty() ? tree_names[std::size_t(tree)]
                                                                                           : "tree " + std::to_string(tree);
  };
  std::vector<std::pair<std::string, std::function<bool(std::int32_t)>>> groups{{"all", [](std::int32_t) { return true; }}};
  std::vector<std::string> kinds, names;
  for (const auto& v : m.vessels) {
    if (std::find(kinds.begin(), kinds.end(), kindOf(v.tree)) == kinds.end()) kinds.push_back(kindOf(v.tree));
    if (std::find(names.begin(), names.end(), nameOf(v.tree)) == names.end()) names.push_back(nameOf(v.tree));
  }
  if (kinds.size() > 1)
    for (const auto& k : kinds) groups.emplace_back("kind " + k, [&, k](std::int32_t tree) { return kindOf(tree) == k; });
  if (names.size() > kinds.size())  // a kind of several trees (inlets): each tree too
    for (const auto& nm : names) groups.emplace_back("tree " + nm, [&, nm](std::int32_t tree) { return nameOf(tree) == nm; });
  for (const auto& [name, in] : groups) {
    MorphometryGroup g;
    g.name = name;
    for (const auto& v : m.vessels)
      if (in(v.tree) && (g.trees.empty() || g.trees.back() != v.tree)) g.trees.push_back(v.tree);
    std::sort(g.trees.begin(), g.trees.end());
    g.trees.erase(std::unique(g.trees.begin(), g.trees.end()), g.trees.end());
    std::map<std::string, std::vector<double>> values;
    std::vector<Vec3> terminal_points;
    for (std::size_t k = 0; k < m.vessels.size(); ++k) {
      const auto& v = m.vessels[k];
      if (!in(v.tree)) continue;
      ++g.vessels;
      for (const auto& [key, value] : vesselStatistics()) values[key].push_back(value(v));
      if (v.terminal) {
        ++g.terminals;
        values["terminal_path_length_mm"].push_back(v.path_length_to_root_mm + v.length_mm);
        values["terminal_generation"].push_back(v.generation);
        terminal_points.push_back(t.position[std::size_t(v.id)]);
      }
      g.junctions += children[k].size() > 2;
    }
    std::vector<std::pair<double, double>> ratios;
    std::vector<std::vector<std::pair<double, double>>> band_ratios(options.murray_band_edges_mm.size() + 1);
    std::vector<std::vector<double>> band_exponents(band_ratios.size());
    for (const auto& b : m.bifurcations) {
      if (!in(b.tree)) continue;
      ++g.bifurcations;
      for (const auto& [key, value] : bifurcationStatistics()) values[key].push_back(value(b));
      std::size_t band = 0;
      while (band < options.murray_band_edges_mm.size() && b.r_parent_mm >= options.murray_band_edges_mm[band]) ++band;
      if (std::isfinite(b.murray_exponent)) {
        const std::pair<double, double> x{b.r_large_mm / b.r_parent_mm, b.r_small_mm / b.r_parent_mm};
        ratios.push_back(x);
        band_ratios[band].push_back(x);
        band_exponents[band].push_back(b.murray_exponent);
      }
    }
    for (auto& [key, vals] : values) g.summaries[key] = summarise(vals);
    std::vector<int> topological(m.vessels.size());
    for (std::size_t k = 0; k < m.vessels.size(); ++k) topological[k] = m.vessels[k].strahler;
    const auto by_topology = orderTable(m, children, in, topological);
    g.strahler = by_topology.orders;
    g.horton_branching = by_topology.horton.branching;
    g.horton_length = by_topology.horton.length;
    g.horton_diameter = by_topology.horton.diameter;
    const auto by_diameter = orderTable(m, children, in, diameterDefinedOrders(m, in, topological));
    g.diameter_orders = by_diameter.orders;
    g.horton_by_diameter = by_diameter.horton;
    for (std::size_t band = 0; band < band_ratios.size(); ++band) {
      MurrayBand mb;
      mb.lower_mm = band == 0 ? 0 : options.murray_band_edges_mm[band - 1];
      mb.upper_mm = band < options.murray_band_edges_mm.size() ? options.murray_band_edges_mm[band] : INFINITY;
      mb.bifurcations = std::int64_t(band_exponents[band].size());
      mb.median_exponent = summarise(band_exponents[band]).median;
      mb.fitted_exponent = fittedMurray(band_ratios[band]);
      g.murray_bands.push_back(mb);
    }
    g.murray_fitted = fittedMurray(ratios);
    g.terminal_nearest_neighbour_mm = meanNearestNeighbour(terminal_points);
    m.groups.push_back(std::move(g));
  }
  return m;
}

nlohmann::ordered_json Morphometry::toJson() const {
  using Json = nlohmann::ordered_json;
  Json groups_json = Json::array();
  for (const auto& g : groups) {
    Json s = Json::object();
    for (const auto& [k, v] : g.summaries)
      s[k] = Json{{"count", v.count},           {"mean", numberOrNull(v.mean)}, {"sd", numberOrNull(v.sd)},         {"min", numberOrNull(v.min)},
                  {"p05", numberOrNull(v.p05)}, {"p25", numberOrNull(v.p25)},   {"median", numberOrNull(v.median)}, {"p75", numberOrNull(v.p75)},
                  {"p95", numberOrNull(v.p95)}, {"max", numberOrNull(v.max)}};
    const auto orderList = [&](const std::vector<StrahlerOrder>& table) {
      Json orders = Json::array();
      for (const auto& o : table)
        orders.push_back(Json{{"order", o.order},
                              {"vessels", o.vessels},
                              {"elements", o.elements},
                              {"mean_element_length_mm", numberOrNull(o.mean_element_length_mm)},
                              {"mean_element_diameter_mm", numberOrNull(o.mean_element_diameter_mm)}});
      return orders;
    };
    const auto horton = [&](const HortonRatios& h) {
      return Json{{"branching", numberOrNull(h.branching)}, {"length", numberOrNull(h.length)}, {"diameter", numberOrNull(h.diameter)}};
    };
    Json bands = Json::array();
    for (const auto& b : g.murray_bands)
      bands.push_back(Json{{"parent_radius_mm", rangeJson(b.lower_mm, b.upper_mm)},
                           {"bifurcations", b.bifurcations},
                           {"median_exponent", numberOrNull(b.median_exponent)},
                           {"fitted_exponent", numberOrNull(b.fitted_exponent)}});
    groups_json.push_back(Json{{"group", g.name},
                               {"vessels", g.vessels},
                               {"bifurcations", g.bifurcations},
                               {"junctions", g.junctions},
                               {"terminals", g.terminals},
                               {"terminal_nearest_neighbour_mm", numberOrNull(g.terminal_nearest_neighbour_mm)},
                               {"murray_fitted_exponent", numberOrNull(g.murray_fitted)},
                               {"murray_bands", bands},
                               {"strahler_orders", orderList(g.strahler)},
                               {"horton_ratios", horton({g.horton_branching, g.horton_length, g.horton_diameter})},
                               {"diameter_defined_orders", orderList(g.diameter_orders)},
                               {"horton_ratios_by_diameter", horton(g.horton_by_diameter)},
                               {"summaries", s}});
  }
  return Json{{"groups", groups_json},
              {"definitions",
               {{"vessel", "from a root or branching point to the next branching point or terminal, through curve pieces"},
                {"radius_mm", "length-weighted mean radius of the vessel's pieces"},
                {"distance_metric", "length / chord (Bullitt et al. 2003)"},
                {"inflections", "changes of the turning direction (binormal reversals) along the vessel"},
                {"sum_of_angles_per_mm", "Σ sqrt(in-plane² + torsion²) angles at its interior points / length, rad/mm (Bullitt et al. 2003)"},
                {"angles", "between the directions of the vessels' pieces at the branching point; 0 = straight on"},
                {"asymmetry", "r_small / r_large of the daughters"},
                {"area_ratio", "(r_large² + r_small²) / r_parent²: the daughters' cross-sections over the parent's"},
                {"daughter_area_ratio", "r_small² / r_large²: the smaller daughter's cross-section over the larger's"},
                {"murray_exponent", "γ solving r_parent^γ = r_large^γ + r_small^γ; fitted: γ minimising Σ (x_large^γ + x_small^γ − 1)²"},
                {"strahler", "terminal vessels 1; a parent takes its children's highest order, plus one when two or more children share it"},
                {"horton_ratios", "from least-squares lines through log(element count, mean length, mean diameter) against order"},
                {"diameter_defined_orders",
                 "Strahler orders redrawn by diameter until fewer than 1 % of vessels move: each order's range ends halfway between its mean + SD "
                 "and the next order's mean − SD (Kassab et al. 1993; Jiang et al. 1994)"}}}};
}

std::string Morphometry::vesselName(std::int32_t vessel) const {
  const std::int32_t id = vessels[std::size_t(vessel)].id;
  return std::size_t(id) < segment_names.size() && !segment_names[std::size_t(id)].empty() ? segment_names[std::size_t(id)] : std::to_string(id);
}

std::string Morphometry::vesselsCsv() const {
  std::ostringstream o;
  o << "vessel,tree,parent,pieces,length_mm,chord_mm,radius_mm,length_over_radius,distance_metric,inflections,sum_of_angles_per_mm,"
       "path_length_to_root_mm,generation,strahler,terminal\n";
  for (std::size_t k = 0; k < vessels.size(); ++k) {
    const auto& v = vessels[k];
    o << vesselName(std::int32_t(k)) << ',' << v.tree << ',' << (v.parent >= 0 ? vesselName(v.parent) : "") << ',' << v.pieces << ','
      << number(v.length_mm) << ',' << number(v.chord_mm) << ',' << number(v.radius_mm) << ',' << number(v.length_over_radius) << ','
      << number(v.distance_metric) << ',' << v.inflections << ',' << number(v.sum_of_angles_per_mm) << ',' << number(v.path_length_to_root_mm) << ','
      << v.generation << ',' << v.strahler << ',' << (v.terminal ? 1 : 0) << '\n';
  }
  return o.str();
}

std::string Morphometry::bifurcationsCsv() const {
  std::ostringstream o;
  o << "tree,parent,daughter_large,daughter_small,r_parent_mm,r_large_mm,r_small_mm,angle_large_deg,angle_small_deg,angle_between_deg,"
       "out_of_plane_deg,asymmetry,area_ratio,daughter_area_ratio,murray_exponent\n";
  for (const auto& b : bifurcations)
    o << b.tree << ',' << vesselName(b.parent) << ',' << vesselName(b.daughter_large) << ',' << vesselName(b.daughter_small) << ','
      << number(b.r_parent_mm) << ',' << number(b.r_large_mm) << ',' << number(b.r_small_mm) << ',' << number(b.angle_large_deg) << ','
      << number(b.angle_small_deg) << ',' << number(b.angle_between_deg) << ',' << number(b.out_of_plane_deg) << ',' << number(b.asymmetry) << ','
      << number(b.area_ratio) << ',' << number(b.daughter_area_ratio) << ',' << number(b.murray_exponent) << '\n';
  return o.str();
}

}  // namespace angiosynth
