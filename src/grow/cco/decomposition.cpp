#include "grow/cco/decomposition.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <mutex>
#include <tuple>

#include "core/rng.hpp"
#include "grow/common/intersections.hpp"
#include "physics/hemodynamics.hpp"

namespace angiosynth {
namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }

// Rounds of regrowing the parts whose vessels meet others before the join gives up (and reports them).
constexpr int kMaxRegrowRounds = 4;

// Failed draws in a row before the trunk gives up, and of those the draws far enough from every
// vessel that still found no connection (a whole tree's limits are 2·10⁶ and 5,000): a trunk of
// a few terminals over the whole domain that fits showed at most a few of the latter in a row
// (docs/benchmarks.md).
constexpr std::int64_t kTrunkDraws = 20000;
constexpr std::int64_t kTrunkUnconnectable = 2000;

// Domain voxels per terminal spacing from which the parts' grids keep the domain's voxel.
constexpr double kFineAgainstSpacing = 4;

// Empty voxels around a part's grid, so that its border has outside voxels to measure depth from.
constexpr int kPartMargin = 2;

// -2 if p lies within the clearance of a trunk vessel; else the part whose root is within
// 1.5 domain voxels of p (where its cell starts), or -1.
int trunkZone(const CcoTrunk& trunk, const Vec3& p) {
  const auto& T = trunk.tree;
  for (std::int32_t s = 1; s < T.nodeCount(); ++s)
    if (pointSegmentDistance(p, T.position[T.parent[s]], trunk.clearance_end[s]) < trunk.clearance_mm[s]) return -2;
  for (std::size_t i = 0; i < trunk.terminal_node.size(); ++i)
    if (distance(p, T.position[trunk.terminal_node[i]]) < 1.5 * trunk.domain_voxel_mm) return int(i);
  return -1;
}

Vec3 voxelCentre(const DemandMap& m, std::int64_t i, std::int64_t j, std::int64_t k) { return Vec3(i + 0.5, j + 0.5, k + 0.5) * m.voxel_mm; }

// trunkZone for the many points of a grid: the trunk's segments and part roots are listed per
// block of 8³ voxels of the domain's frame (each where it can reach), so that a point tests only
// its block's, in the same order: the same answers, at a cost that does not grow with the trunk.
class TrunkZones {
 public:
  TrunkZones(const CcoTrunk& trunk, const DemandMap& m) : trunk_(trunk), edge_(kBlock * m.voxel_mm) {
    for (int a = 0; a < 3; ++a) blocks_[a] = std::max<std::int64_t>(1, (m.dims[a] + kBlock - 1) / kBlock);
    lists_.resize(std::size_t(blocks_[0] * blocks_[1] * blocks_[2]));
    const double half_diagonal = 0.5 * edge_ * std::sqrt(3.0) * (1 + 1e-9);
    const auto& T = trunk.tree;
    // Item i < 0: segment -i; i >= 0: root i (roots after segments, as trunkZone tests them).
    const auto stamp = [&](std::int32_t item, const Vec3& a, const Vec3& b, double reach) {
      std::array<std::int64_t, 3> lo{}, hi{};
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::clamp<std::int64_t>(std::int64_t(std::floor((std::min(a[k], b[k]) - reach) / edge_)) - 1, 0, blocks_[k] - 1);
        hi[k] = std::clamp<std::int64_t>(std::int64_t(std::floor((std::max(a[k], b[k]) + reach) / edge_)) + 1, 0, blocks_[k] - 1);
      }
      for (std::int64_t z = lo[2]; z <= hi[2]; ++z)
        for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
          for (std::int64_t x = lo[0]; x <= hi[0]; ++x) {
            const Vec3 centre = Vec3(x + 0.5, y + 0.5, z + 0.5) * edge_;
            if (pointSegmentDistance(centre, a, b) < reach + half_diagonal)
              lists_[std::size_t(x + blocks_[0] * (y + blocks_[1] * z))].push_back(item);
          }
    };
    for (std::int32_t seg = 1; seg < T.nodeCount(); ++seg)
      if (trunk.clearance_mm[seg] > 0) stamp(-seg, T.position[T.parent[seg]], trunk.clearance_end[seg], trunk.clearance_mm[seg]);
    for (std::size_t i = 0; i < trunk.terminal_node.size(); ++i) {
      const Vec3 root = T.position[trunk.terminal_node[i]];
      stamp(std::int32_t(i), root, root, 1.5 * trunk.domain_voxel_mm);
    }
  }
  // trunkZone(trunk, p) for p inside the frame.
  int at(const Vec3& p) const {
    std::int64_t b[3];
    for (int k = 0; k < 3; ++k) b[k] = std::clamp<std::int64_t>(std::int64_t(std::floor(p[k] / edge_)), 0, blocks_[k] - 1);
    const auto& T = trunk_.tree;
    for (const std::int32_t item : lists_[std::size_t(b[0] + blocks_[0] * (b[1] + blocks_[1] * b[2]))]) {
      if (item < 0) {
        if (pointSegmentDistance(p, T.position[T.parent[-item]], trunk_.clearance_end[-item]) < trunk_.clearance_mm[-item]) return -2;
      } else if (distance(p, T.position[trunk_.terminal_node[std::size_t(item)]]) < 1.5 * trunk_.domain_voxel_mm) {
        return item;
      }
    }
    return -1;
  }

 private:
  static constexpr std::int64_t kBlock = 8;
  const CcoTrunk& trunk_;
  double edge_;
  std::array<std::int64_t, 3> blocks_{};
  std::vector<std::vector<std::int32_t>> lists_;  // per block: segments (as -s) in order, then roots
};

// Physics of a part: its share of the flow, and part_pressure_share of the drop at its root.
PhysicsParameters partPhysics(const CcoDecompositionOptions& opt, std::int64_t part_terminals) {
  PhysicsParameters p = opt.cco.physics;
  p.perfusion_flow = opt.cco.physics.perfusion_flow * double(part_terminals) / double(opt.cco.terminals);
  p.perfusion_pressure = p.terminal_pressure + opt.part_pressure_share * (opt.cco.physics.perfusion_pressure - p.terminal_pressure);
  return p;
}

// Grows the trunk with options o and continues each terminal into its part's root (see
// CcoTrunk); false if a terminal has no room for that.
bool growTrunk(const GrowthDomain& domain, const CcoDecompositionOptions& opt, const CcoOptions& o, CcoTrunk& trunk) {
  GrowthReport rep;
  try {
    trunk.tree = growCco(domain, o, rep);
  } catch (const GrowthError& e) {
    throw GrowthError("the trunk of " + std::to_string(opt.parts) + " parts (its vessels twice as thick as they will be) does not fit: " + e.what() +
                      "; allowed: fewer parts, a smaller perfusion_flow or a larger domain");
  }
  auto& T = trunk.tree;
  trunk.terminal_node.clear();
  for (std::int32_t i = 1; i < T.nodeCount(); ++i)
    if (T.isTerminal(i)) trunk.terminal_node.push_back(i);
  const DemandMap& m = domain.frame();
  // The parts' grids halve the domain's voxel where it is coarse against the terminals' spacing
  // (V/N)^(1/d), so that the band a part loses along its borders stays thin against that
  // spacing; where the voxel is already a quarter of the spacing or less, halving it would only
  // multiply each part's grid, and its depth map, by 2^d.
  const double spacing = domain.terminalSpacing(opt.cco.terminals);
  trunk.part_voxel_mm = opt.part_voxel_mm > 0 ? opt.part_voxel_mm : spacing >= kFineAgainstSpacing * m.voxel_mm ? m.voxel_mm : m.voxel_mm / 2;
  trunk.clearance_mm.assign(std::size_t(T.nodeCount()), 0.0);
  trunk.domain_voxel_mm = m.voxel_mm;
  trunk.clearance_end = T.position;
  for (std::int32_t s = 1; s < T.nodeCount(); ++s) trunk.clearance_mm[s] = T.radius[s] + m.voxel_mm;
  // Each terminal vessel runs on, with a bend where it ended, by a short stretch (straight on or
  // sideways, wherever the domain is deepest and no other clearance lies) whose end is the part's
  // root: from there its vessels keep out of every trunk vessel's clearance, the stretch's
  // included, and only the part's first segments come near the trunk.
  for (auto& t : trunk.terminal_node) {
    const Vec3 end = T.position[t], along = unit(end - T.position[T.parent[t]]);
    std::vector<Vec3> directions{along};
    for (int z = -1; z <= 1; ++z)
      for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
          if ((x | y | z) != 0 && (domain.dimension() == 3 || z == 0)) directions.push_back(unit(Vec3(x, y, z)));
    // The stretch is twice the clearance long (longer than twice the vessel's radius, which the
    // clearance bounds), kept clear like the vessel it continues except for its last clearance,
    // whose end is the root; it must lie in the domain by the radius the clearance allows for (the
    // clearance less a voxel) and clear of the others.
    const double c = trunk.clearance_mm[t], length = 2 * c;
    double best_depth = 0;
    Vec3 best = end;
    for (const Vec3& d : directions) {
      if (dot(d, along) < 0) continue;  // back over the vessel
      const Vec3 p = end + d * (length * (1 + 1e-9));
      if (domain.dimension() == 2 && p.z != end.z) continue;
      double depth = std::numeric_limits<double>::infinity();
      bool clear = true;
      for (int j = 1; j <= 8 && clear; ++j) {
        const Vec3 q = end + d * (length * j / 8);
        depth = std::min(depth, domain.depth(q));
        clear = depth >= c - m.voxel_mm && (j <= 4 || trunkZone(trunk, q) != -2);
      }
      if (clear && depth > best_depth) best_depth = depth, best = p;
    }
    if (best == end) return false;
    const Vec3 d = unit(best - end);
    t = T.addNode(best, t);
    trunk.clearance_mm.push_back(c);
    trunk.clearance_end.push_back(end + d * (length - c));
  }
  return true;
}

}  // namespace

CcoTrunk planCcoTrunk(const GrowthDomain& domain, const CcoDecompositionOptions& opt) {
  if (opt.parts < 2) throw GrowthError("a decomposition needs at least 2 parts");
  if (opt.cco.terminals < opt.parts) throw GrowthError("fewer terminals than parts: each part grows at least one");
  CcoTrunk trunk;
  CcoOptions o = opt.cco;
  o.terminals = opt.parts;
  o.organ_scale = false;
  // A few terminals over the whole domain: when this many draws in a row fail, its vessels do not fit.
  o.max_draws = std::min<std::int64_t>(o.max_draws, kTrunkDraws);
  o.max_unconnectable = std::min<std::int64_t>(o.max_unconnectable, kTrunkUnconnectable);
  // Grown with its radii at the bound on their final values (a drop trunk_radius_factor⁴ times
  // smaller), so that its own checks (length, overlap, inside) hold for the whole tree's radii.
  o.physics.perfusion_pressure =
      o.physics.terminal_pressure + (o.physics.perfusion_pressure - o.physics.terminal_pressure) / std::pow(opt.trunk_radius_factor, 4);
  // Grown again with its terminals drawn deeper when one lies too near the border to continue.
  for (int attempt = 0;; ++attempt) {
    if (growTrunk(domain, opt, o, trunk)) break;
    if (attempt == 2)
      throw GrowthError(
          "a trunk terminal lies too near the domain's border, or other trunk vessels, for its part to start beyond the trunk's "
          "clearance; allowed: fewer parts or another seed");
    o.terminal_depth = 3 * *std::max_element(trunk.clearance_mm.begin(), trunk.clearance_mm.end());
  }
  PhysicsParameters trunk_physics = o.physics;
  trunk_physics.total_terminals = opt.parts;
  solveTree(trunk.tree, trunk_physics);  // the stretches, at the same bound
  const DemandMap& m = domain.frame();
  // The cells: every voxel of the domain outside the trunk's clearance goes to the terminal
  // nearest along paths that stay in the domain and out of the clearance (a multi-source
  // Dijkstra over 26 neighbours, ties to the lower part), so that each cell is in one piece and
  // reachable from its root. The parts' shares of N: the demand of their cells, at least one each.
  const auto n_vox = std::size_t(m.voxelCount());
  trunk.cell.assign(n_vox, -1);
  std::vector<std::int16_t> zone(n_vox, -2);  // -2 closed (outside or clearance), -1 open, else a ball's part
  const TrunkZones zones(trunk, m);
  tbb::parallel_for(tbb::blocked_range<std::int32_t>(0, m.dims[2]), [&](const tbb::blocked_range<std::int32_t>& r) {
    for (std::int32_t z = r.begin(); z < r.end(); ++z)
      for (std::int32_t y = 0; y < m.dims[1]; ++y)
        for (std::int32_t x = 0; x < m.dims[0]; ++x) {
          const auto v = std::size_t(m.flat(x, y, z));
          if (m.demand[v] > 0) zone[v] = std::int16_t(zones.at(voxelCentre(m, x, y, z)));
        }
  });
  {
    struct Item {
      float d;
      std::int16_t part;
      std::int64_t v;
      bool operator>(const Item& o) const { return std::tie(d, part, v) > std::tie(o.d, o.part, o.v); }
    };
    // Dijkstra's order without a heap: a step is at least 1 voxel, so everything at distance
    // [b, b + 1) is known once the distances below b are settled, and it reaches no further than
    // b + 1 + √3. Buckets of width 1, three alive, each sorted as the heap would pop it.
    std::array<std::vector<Item>, 3> ring;
    std::vector<float> dist(n_vox, std::numeric_limits<float>::infinity());
    for (std::size_t v = 0; v < n_vox; ++v)
      if (zone[v] >= 0) dist[v] = 0, ring[0].push_back({0.0f, std::int16_t(zone[v]), std::int64_t(v)});
    const std::int64_t nx = m.dims[0], ny = m.dims[1], nz = m.dims[2];
    for (std::int64_t b = 0; !(ring[0].empty() && ring[1].empty() && ring[2].empty()); ++b) {
      auto& bucket = ring[std::size_t(b % 3)];
      std::sort(bucket.begin(), bucket.end(), [](const Item& l, const Item& r) { return r > l; });
      for (const Item& it : bucket) {
        if (trunk.cell[std::size_t(it.v)] >= 0) continue;
        trunk.cell[std::size_t(it.v)] = it.part;
        const std::int64_t x = it.v % nx, y = (it.v / nx) % ny, z = it.v / (nx * ny);
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const std::int64_t X = x + dx, Y = y + dy, Z = z + dz;
              if ((dx | dy | dz) == 0 || X < 0 || Y < 0 || Z < 0 || X >= nx || Y >= ny || Z >= nz) continue;
              const auto w = std::size_t(X + nx * (Y + ny * Z));
              if (zone[w] == -2 || trunk.cell[w] >= 0) continue;
              const float d = it.d + float(std::sqrt(double(dx * dx + dy * dy + dz * dz)));
              if (d < dist[w]) dist[w] = d, ring[std::size_t(std::int64_t(d) % 3)].push_back({d, it.part, std::int64_t(w)});
            }
      }
      bucket.clear();
    }
  }
  const std::size_t k = trunk.terminal_node.size();
  std::vector<double> weight(k, 0.0);
  double unreached = 0;
  for (std::size_t v = 0; v < n_vox; ++v) {
    if (!(m.demand[v] > 0) || zone[v] == -2) continue;
    const double w = domain.demandWeighted() ? double(m.demand[v]) : 1.0;
    if (trunk.cell[v] >= 0)
      weight[std::size_t(trunk.cell[v])] += w;
    else
      unreached += w;
  }
  double total = 0;
  for (double w : weight) total += w;
  if (!(total > 0)) throw GrowthError("no voxel of the domain is left to the parts: lower the trunk clearance or use finer voxels");
  // Before any part grows: a part without room would only fail once the others had grown.
  for (std::size_t i = 0; i < k; ++i)
    if (!(weight[i] > 0))
      throw GrowthError("part " + std::to_string(i) +
                        " has no voxel left beside the trunk's vessels; allowed: fewer parts, finer voxels or a smaller perfusion_flow");
  std::vector<double> shares(k);
  for (std::size_t i = 0; i < k; ++i) shares[i] = weight[i] / total;
  trunk.part_terminals = terminalQuotas(shares, opt.cco.terminals - std::int64_t(k));
  for (auto& n : trunk.part_terminals) ++n;
  trunk.unreached_share = unreached / (total + unreached);
  return trunk;
}

GrowthDomain ccoPartDomain(const GrowthDomain& domain, const CcoTrunk& trunk, int part, Vec3& offset_mm) {
  const DemandMap& m = domain.frame();
  const double h = trunk.part_voxel_mm;
  std::array<std::int32_t, 3> lo{m.dims[0], m.dims[1], m.dims[2]}, hi{-1, -1, -1};
  for (std::int32_t z = 0; z < m.dims[2]; ++z)
    for (std::int32_t y = 0; y < m.dims[1]; ++y)
      for (std::int32_t x = 0; x < m.dims[0]; ++x)
        if (trunk.cell[std::size_t(m.flat(x, y, z))] == part) {
          const std::array<std::int32_t, 3> c{x, y, z};
          for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
        }
  if (hi[0] < 0)
    throw GrowthError("part " + std::to_string(part) +
                      " has no voxel left beside the trunk's vessels; allowed: fewer parts, finer voxels or a smaller perfusion_flow");
  const bool flat = domain.dimension() == 2;
  DemandMap pm;
  pm.voxel_mm = h;
  std::array<std::int64_t, 3> origin{};
  for (int a = 0; a < 3; ++a) {
    if (a == 2 && flat) {  // one slice, through the plane
      origin[a] = std::int64_t(std::floor(domain.planeZ() / h));
      pm.dims[a] = 1;
      continue;
    }
    origin[a] = std::int64_t(std::floor(lo[a] * m.voxel_mm / h)) - kPartMargin;
    pm.dims[a] = std::int32_t(std::int64_t(std::ceil((hi[a] + 1) * m.voxel_mm / h)) + kPartMargin - origin[a]);
  }
  offset_mm = Vec3(double(origin[0]), double(origin[1]), double(origin[2])) * h;
  // A voxel of the part's grid is the part's when its centre is in the cell, inside the domain by
  // half a voxel's diagonal (a vessel inside the part is then inside the domain), out of the
  // trunk's clearance (but in its own ball), and its neighbours' centres lie in no other cell (a
  // gap of two voxels between parts, wider than the depth's half-voxel error).
  const double inset = 0.5 * h * (flat ? std::sqrt(2.0) : std::sqrt(3.0));
  const TrunkZones zones(trunk, m);
  const auto cellAt = [&](const Vec3& c) {
    const auto v = m.voxelAt(c);
    return v >= 0 ? trunk.cell[std::size_t(v)] : std::int16_t(-1);
  };
  // Voxels of the domain's grid next to another cell: only there do the neighbours need a look.
  std::vector<std::uint8_t> border(std::size_t(m.voxelCount()), 0);
  tbb::parallel_for(tbb::blocked_range<std::int32_t>(std::max(0, lo[2] - 1), std::min(m.dims[2], hi[2] + 2)),
                    [&](const tbb::blocked_range<std::int32_t>& r) {
                      for (std::int32_t z = r.begin(); z < r.end(); ++z)
                        for (std::int32_t y = std::max(0, lo[1] - 1); y < std::min(m.dims[1], hi[1] + 2); ++y)
                          for (std::int32_t x = std::max(0, lo[0] - 1); x < std::min(m.dims[0], hi[0] + 2); ++x) {
                            bool near_other = false;
                            for (int dz = -1; dz <= 1; ++dz)
                              for (int dy = -1; dy <= 1; ++dy)
                                for (int dx = -1; dx <= 1; ++dx) {
                                  const std::int32_t X = x + dx, Y = y + dy, Z = z + dz;
                                  if (X < 0 || Y < 0 || Z < 0 || X >= m.dims[0] || Y >= m.dims[1] || Z >= m.dims[2]) continue;
                                  const auto c = trunk.cell[std::size_t(m.flat(X, Y, Z))];
                                  near_other = near_other || (c >= 0 && c != part);
                                }
                            border[std::size_t(m.flat(x, y, z))] = near_other;
                          }
                    });
  pm.demand.assign(std::size_t(pm.voxelCount()), 0.0f);
  tbb::parallel_for(tbb::blocked_range<std::int32_t>(0, pm.dims[2]), [&](const tbb::blocked_range<std::int32_t>& r) {
    for (std::int32_t z = r.begin(); z < r.end(); ++z)
      for (std::int32_t y = 0; y < pm.dims[1]; ++y)
        for (std::int32_t x = 0; x < pm.dims[0]; ++x) {
          Vec3 c = offset_mm + voxelCentre(pm, x, y, z);
          if (flat) c.z = domain.planeZ();
          const auto v = m.voxelAt(c);
          if (v < 0 || trunk.cell[std::size_t(v)] != part || !(domain.depth(c) >= inset)) continue;
          const int zone = zones.at(c);
          if (zone == -2 || (zone >= 0 && zone != part)) continue;
          if (border[std::size_t(v)]) {
            bool alone = true;
            for (int dz = flat ? 0 : -1; dz <= (flat ? 0 : 1) && alone; ++dz)
              for (int dy = -1; dy <= 1 && alone; ++dy)
                for (int dx = -1; dx <= 1 && alone; ++dx) {
                  const auto other = cellAt(c + Vec3(dx, dy, dz) * h);
                  alone = other < 0 || other == part;
                }
            if (!alone) continue;
          }
          const float w = domain.demandWeighted() ? m.demand[std::size_t(v)] : 1.0f;
          pm.demand[std::size_t(pm.flat(x, y, z))] = w;
        }
  });
  pm.supply_index.assign(std::size_t(pm.voxelCount()), 0);
  pm.supply_sets = {{}};
  return GrowthDomain::mask(std::move(pm), domain.demandWeighted());
}

CcoPart growCcoPart(const GrowthDomain& domain, const CcoTrunk& trunk, int part, const CcoDecompositionOptions& opt, int attempt) {
  const auto t0 = std::chrono::steady_clock::now();
  Vec3 offset;
  const GrowthDomain pd = ccoPartDomain(domain, trunk, part, offset);
  CcoOptions o = opt.cco;
  o.terminals = trunk.part_terminals[std::size_t(part)];
  o.root_mm = trunk.tree.position[trunk.terminal_node[std::size_t(part)]] - offset;
  o.seed = mix64(opt.cco.seed + 0x9e3779b97f4a7c15ULL * std::uint64_t(part + 1) + 0xd1b54a32d192ed03ULL * std::uint64_t(attempt));
  o.physics = partPhysics(opt, o.terminals);
  CcoPart out;
  out.attempt = attempt;
  out.tree = growCco(pd, o, out.report);
  for (auto& p : out.tree.position) p = p + offset;
  out.tree.position[0] = trunk.tree.position[trunk.terminal_node[std::size_t(part)]];  // exactly, whatever the rounding
  out.seconds = secondsSince(t0);
  return out;
}

VascularTree joinCcoParts(const GrowthDomain& domain, const CcoTrunk& trunk, const std::vector<CcoPart>& parts, const CcoDecompositionOptions& opt,
                          CcoDecompositionSummary& sum) {
  const auto t0 = std::chrono::steady_clock::now();
  if (parts.size() != trunk.terminal_node.size()) throw GrowthError("the join needs every part");
  const auto& T = trunk.tree;
  VascularTree J;
  J.reserve(std::size_t(2 * opt.cco.terminals + 1));
  // The trunk, parents before children, then each part hung from its terminal.
  std::vector<std::int32_t> id(std::size_t(T.nodeCount()), -1);
  for (auto i : T.topDownOrder()) id[std::size_t(i)] = J.addNode(T.position[i], T.parent[i] < 0 ? -1 : id[std::size_t(T.parent[i])]);
  std::vector<std::int32_t> part_root_segment(parts.size(), -1);
  std::vector<int> owner(std::size_t(J.nodeCount()), -1);
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const VascularTree& P = parts[k].tree;
    if (P.nodeCount() < 2 || !(P.position[0] == T.position[trunk.terminal_node[k]]))
      throw GrowthError("part " + std::to_string(k) + " does not start at its trunk terminal");
    std::vector<std::int32_t> pid(std::size_t(P.nodeCount()), -1);
    owner.resize(std::size_t(J.nodeCount() + P.nodeCount() - 1), int(k));
    pid[0] = id[std::size_t(trunk.terminal_node[k])];
    for (auto i : P.topDownOrder())
      if (i != 0) pid[std::size_t(i)] = J.addNode(P.position[i], pid[std::size_t(P.parent[i])]);
    const std::int32_t root_segment = P.rootSegment();
    if (root_segment < 1) throw GrowthError("part " + std::to_string(k) + " has no vessel");
    part_root_segment[k] = pid[std::size_t(root_segment)];
  }
  PhysicsParameters physics = opt.cco.physics;
  physics.total_terminals = opt.cco.terminals;
  solveTree(J, physics);
  sum.parts = int(parts.size());
  sum.terminals = J.totalTerminals();
  sum.unreached_share = trunk.unreached_share;
  // What the parts' own checks assumed, against the whole tree.
  sum.largest_part_scale = 0;
  sum.smallest_part_scale = std::numeric_limits<double>::infinity();
  sum.smallest_part_pressure_share = std::numeric_limits<double>::infinity();
  sum.repaired_terminals = 0;
  const double drop = opt.cco.physics.perfusion_pressure - opt.cco.physics.terminal_pressure;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const double scale = J.radius[part_root_segment[k]] / parts[k].tree.radius[parts[k].tree.rootSegment()];
    sum.largest_part_scale = std::max(sum.largest_part_scale, scale);
    sum.smallest_part_scale = std::min(sum.smallest_part_scale, scale);
    const double share = (J.pressure[id[std::size_t(trunk.terminal_node[k])]] - opt.cco.physics.terminal_pressure) / drop;
    sum.smallest_part_pressure_share = std::min(sum.smallest_part_pressure_share, share);
    sum.repaired_terminals += parts[k].report.repaired_terminals;
  }
  sum.largest_trunk_radius_share = 0;
  for (std::int32_t s = 1; s < T.nodeCount(); ++s)
    if (trunk.clearance_mm[s] > 0)
      sum.largest_trunk_radius_share = std::max(sum.largest_trunk_radius_share, J.radius[id[std::size_t(s)]] / trunk.clearance_mm[s]);
  // The exact checks of the whole tree.
  const auto pairs = intersectingPairs(J, domain.lo(), domain.hi());
  sum.intersecting_pairs = std::int64_t(pairs.size());
  sum.offending_parts.clear();
  for (auto [x, y] : pairs)
    for (int k : {owner[std::size_t(x)], owner[std::size_t(y)]})
      if (k >= 0) sum.offending_parts.push_back(k);
  std::sort(sum.offending_parts.begin(), sum.offending_parts.end());
  sum.offending_parts.erase(std::unique(sum.offending_parts.begin(), sum.offending_parts.end()), sum.offending_parts.end());
  sum.short_segments = sum.outside_segments = 0;
  for (std::int32_t s = 1; s < J.nodeCount(); ++s) {
    if (!(J.length[s] > 2 * J.radius[s])) ++sum.short_segments;
    if (!domain.capsuleInside(J.position[J.parent[s]], J.position[s], J.radius[s], J.parent[s] == 0)) ++sum.outside_segments;
  }
  sum.join_seconds = secondsSince(t0);
  return J;
}

VascularTree joinCcoPartsRegrowing(const GrowthDomain& domain, const CcoTrunk& trunk, std::vector<CcoPart>& parts, const CcoDecompositionOptions& opt,
                                   CcoDecompositionSummary& sum) {
  // A part whose vessels meet another part's or the trunk's (near where it joins the trunk: rare)
  // is grown again from its next seed.
  for (int round = 1;; ++round) {
    VascularTree joined = joinCcoParts(domain, trunk, parts, opt, sum);
    if (sum.offending_parts.empty() || round > kMaxRegrowRounds) return joined;
    const auto t1 = std::chrono::steady_clock::now();
    const auto again = sum.offending_parts;
    tbb::parallel_for(std::size_t(0), again.size(), [&](std::size_t i) {
      const int k = again[i];
      parts[std::size_t(k)] = growCcoPart(domain, trunk, k, opt, parts[std::size_t(k)].attempt + 1);
    });
    sum.regrown_parts += std::int64_t(again.size());
    sum.parts_seconds += secondsSince(t1);
  }
}

GrowthReport decomposedReport(const std::vector<CcoPart>& parts, const CcoDecompositionSummary& sum, const VascularTree& joined) {
  GrowthReport r;
  // The parts' counts add up; the whole tree's checks replace theirs.
  for (const auto& p : parts) {
    GrowthReport q = p.report;
    const auto from = q.counts();
    const auto into = r.counts();
    for (std::size_t i = 0; i < into.size(); ++i) *into[i] += *from[i];
    r.repair_rounds = std::max(r.repair_rounds, q.repair_rounds);
  }
  r.intersecting_pairs = sum.intersecting_pairs;
  r.short_segments = sum.short_segments;
  r.outside_segments = sum.outside_segments;
  r.root_radius_mm = joined.nodeCount() > 1 ? joined.radius[joined.rootSegment()] : 0;
  r.decomposition = sum;
  return r;
}

VascularTree growCcoDecomposed(const GrowthDomain& domain, const CcoDecompositionOptions& opt, GrowthReport& report, const ProgressFn& progress) {
  CcoDecompositionSummary sum;
  auto t0 = std::chrono::steady_clock::now();
  const CcoTrunk trunk = planCcoTrunk(domain, opt);
  sum.trunk_seconds = secondsSince(t0);
  t0 = std::chrono::steady_clock::now();
  std::vector<CcoPart> parts(trunk.terminal_node.size());
  std::mutex progress_mutex;
  std::int64_t done = 0;
  tbb::parallel_for(std::size_t(0), parts.size(), [&](std::size_t k) {
    parts[k] = growCcoPart(domain, trunk, int(k), opt);
    if (!progress) return;
    const std::lock_guard lock(progress_mutex);
    done += trunk.part_terminals[k];
    progress(done, opt.cco.terminals);
  });
  sum.parts_seconds = secondsSince(t0);
  sum.slowest_part_seconds = 0;
  for (const auto& p : parts) sum.slowest_part_seconds = std::max(sum.slowest_part_seconds, p.seconds);
  VascularTree joined = joinCcoPartsRegrowing(domain, trunk, parts, opt, sum);
  report = decomposedReport(parts, sum, joined);
  return joined;
}

}  // namespace angiosynth
