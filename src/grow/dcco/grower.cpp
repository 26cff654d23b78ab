#include "grow/dcco/grower.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>

#include "core/rng.hpp"
#include "core/physical_ranges.hpp"
#include "grow/common/intersections.hpp"
#include "core/segment_index.hpp"
#include "grow/dcco/lattice.hpp"
#include "physics/hemodynamics.hpp"

namespace angiosynth {
namespace {

constexpr double kEtaRef = 3.6e-3;  // Pa*s: reduced resistances are stored in units of 8·kEtaRef/π
// An ancestor is checked again for collisions once its radius has grown by this factor.
constexpr double kRecheckGrowth = 1.02;
// Constraints are checked during growth with this margin on radii, so that the exact radii of
// the stage's final fixed point rarely break them.
constexpr double kMargin = 1.02;
// Full fixed point (and exact relative radii) after the tree has grown by this share.
constexpr double kRefreshShare = 0.02;
// Vessels with ρ = r/r_1 above kThickReach are not found through the grid but from a list of
// those above kThickList (rebuilt at every fixed point, while ρ drifts by a few percent).
constexpr double kThickReach = 0.25, kThickList = 0.2;
// The repair sheds at most this share of a stage's terminals from below one vessel while that
// fixes something (more only when a violation would otherwise stay).
constexpr double kMaxShedShare = 0.05;
// Draws from a stage's Gaussians that may miss its terminal region in a row before growth stops.
constexpr std::int64_t kGaussianMisses = 10'000'000;

// Characteristic length of a domain (eq. 13): the radius of the disc or ball of its measure.
double characteristicLength(const GrowthDomain& d) {
  return d.dimension() == 2 ? std::sqrt(d.measure() / std::numbers::pi) : std::cbrt(3 * d.measure() / (4 * std::numbers::pi));
}

// Murray kernels per stage (γ may differ between stages), or the bands' for every stage.
std::vector<PowerKernel> kernelsOf(const std::vector<double>& gamma_of_stage, const DccoOptions& o) {
  std::vector<PowerKernel> k;
  for (double g : gamma_of_stage) {
    PhysicsParameters p;
    p.murray_exponent = g;
    p.murray_band_edges = o.murray_band_edges;
    p.murray_band_exponents = o.murray_band_exponents;
    k.emplace_back(p);
  }
  return k;
}

// The kernel of the split at node i: that of the stage which made the bifurcation (its new branch).
const PowerKernel& kernelAt(const VascularTree& t, std::int32_t i, const std::vector<PowerKernel>& kernels) {
  const auto c = t.child1[i] >= 0 ? t.child1[i] : i;
  const int st = t.stage[c] >= 0 ? t.stage[c] : 0;
  return kernels[std::min<std::size_t>(std::size_t(st), kernels.size() - 1)];
}

// One level of the path from a new bifurcation to the root, as a trial point would leave it.
struct Level {
  std::int32_t seg, child, other;  // child -1: the level-0 segment; other -1: none (a continuation)
  double beta_child, beta_other, R, V;
  std::int32_t n;  // terminals below
  double w;        // load: flow below in units of the common terminal flow
};

struct Trial {
  std::int32_t s = -1;
  Vec3 b;
  double cost = 0;
  double r[3] = {0, 0, 0};  // proximal part, distal part, new vessel (distal: s, its child, new vessel)
  bool valid = false;
  bool distal = false;  // the new vessel leaves s's distal end (s is not split)
};

class DccoGrower {
 public:
  DccoGrower(const DccoOptions& o, GrowthReport& r, DccoReport& d)
      : o_(o), report_(r), dr_(d), rng_(o.seed, o.sample, Stage::Growth), index_(o.world->lo(), o.world->hi(), o.world->dimension() == 2) {
    for (const auto& st : o.stages) gamma_.push_back(st.gamma);
    kernels_ = kernelsOf(gamma_, o_);
    std::int64_t total = 0;
    for (const auto& st : o.stages) total += st.terminal_count;
    t_.reserve(2 * total + 2 + (o.initial ? std::size_t(o.initial->nodeCount()) : 0));
    if (o.initial) {
      t_ = *o.initial;
      for (std::int32_t i = 0; i < t_.nodeCount(); ++i) t_.stage[i] = -1;
      given_ = t_.nodeCount();
    } else {
      t_.addNode(o.root_mm, -1);
    }
    trees_ = std::int32_t(t_.roots().size());
    r1_ = o.root_radii.empty() ? std::vector<double>(std::size_t(trees_), o.root_radius) : o.root_radii;
    vol_.assign(std::size_t(trees_), 0.0);
    eta_.assign(std::size_t(t_.nodeCount()), o.viscosity.at(o.root_radius));
    rel_.assign(std::size_t(t_.nodeCount()), 1.0);
    checked_.assign(std::size_t(t_.nodeCount()), 0.0);
    load_.assign(std::size_t(t_.nodeCount()), 0.0);
    if (o.initial) {
      solve();
      checked_ = t_.radius;
      index_.refresh(t_, true);
      refuseUnbranchableNetwork();
    }
  }

  // A branch leaves a vessel between its ends, clear of the pieces beside it. A network whose
  // every vessel that may branch is drawn in pieces shorter than its radius (a polyline sampled
  // finely) gives no draw a place to connect: refused here, before millions of draws find none.
  void refuseUnbranchableNetwork() const {
    std::int32_t shortest = -1;
    for (std::int32_t i = 0; i < t_.nodeCount(); ++i) {
      if (t_.isRoot(i) || t_.isLink(i) || !mayBranch(i)) continue;
      if (t_.length[i] >= t_.radius[i]) return;
      if (shortest < 0 || t_.length[i] / t_.radius[i] < t_.length[shortest] / t_.radius[shortest]) shortest = i;
    }
    if (shortest < 0) return;  // nothing may branch: the stages' own checks say so
    const std::string name =
        std::size_t(shortest) < o_.initial_names.size() ? o_.initial_names[std::size_t(shortest)] : "vessel " + std::to_string(shortest);
    throw GrowthError(
        "no vessel of the initial network can take a branch: each one that may is shorter than its radius at the flow it "
        "carries (" +
        name + ": " + show(t_.length[shortest]) + " mm long, radius " + show(t_.radius[shortest]) +
        " mm); allowed: pieces at least as long as their radius (join a polyline's samples)");
  }

  VascularTree run(const ProgressFn& progress) {
    std::int64_t total = 0;
    for (const auto& st : o_.stages) total += st.terminal_count;
    for (std::size_t k = 0; k < o_.stages.size(); ++k) {
      stage_ = int(k);
      const auto& st = o_.stages[k];
      made_ = 0;
      lc_ = characteristicLength(*st.terminals);
      growStage(progress, total);
      repairStage(progress, total);
      dr_.stage_terminals.push_back(made_);
    }
    dr_.viscosity_iterations = solve();
    finalCounts();
    // r_1 and Q are both given, so the pressures follow: a root too thin for its flow would need
    // a drop larger than the root pressure (radii and geometry do not depend on Q).
    double lowest = o_.root_pressure;
    for (std::int32_t i = 1; i < t_.nodeCount(); ++i) lowest = std::min(lowest, t_.pressure[i]);
    if (!(lowest > 0))
      throw GrowthError("the tree carries perfusion_flow " + std::to_string(o_.flow) + " mm^3/s with a pressure drop of " +
                        std::to_string(o_.root_pressure - lowest) + " Pa, more than perfusion_pressure (" + std::to_string(o_.root_pressure) +
                        " Pa): lower perfusion_flow (pressures scale with it; the tree does not change) "
                        "or raise root_radius");
    return std::move(t_);
  }

 private:
  std::int64_t terminalCount() const { return t_.nodeCount() > 1 ? t_.totalTerminals() : 0; }
  const DccoStage& stage() const { return o_.stages[stage_]; }
  double rootRadiusOf(std::int32_t y) const { return r1_[std::size_t(t_.tree[y])]; }
  double radiusOf(std::int32_t y) const { return rootRadiusOf(y) * rel_[y]; }
  // A node of the initial network (never removed; ids below given_ survive every compaction).
  bool givenNode(std::int32_t i) const { return i < given_; }
  // Terminals the current stage made (its vessels that end free).
  std::int64_t stageTerminals() const {
    std::int64_t n = 0;
    for (std::int32_t i = 0; i < t_.nodeCount(); ++i) n += t_.isTerminal(i) && t_.stage[i] == stage_;
    return n;
  }
  double treeVolumeOf(std::int32_t tr) const {
    const double r = r1_[std::size_t(tr)];
    return std::numbers::pi * r * r * t_.cost_ratio[t_.child0[rootOf_[std::size_t(tr)]]];
  }
  double e(std::int32_t y) const { return eta_[y] / kEtaRef; }

  // Algorithm 1 on the whole tree; refreshes ρ, the clear-radius bookkeeping and the index.
  int solve() {
    const int it = solveDccoTree(t_, eta_, o_, gamma_, r1_, &load_);
    rel_.assign(t_.nodeCount(), 1.0);
    for (std::int32_t i = 1; i < t_.nodeCount(); ++i)
      if (!t_.isRoot(i)) rel_[i] = t_.radius[i] / rootRadiusOf(i);
    checked_.resize(t_.nodeCount(), 0.0);
    solved_at_ = t_.nodeCount();
    rootOf_.assign(std::size_t(trees_), -1);
    for (auto r : t_.roots()) rootOf_[std::size_t(t_.tree[r])] = r;
    for (std::int32_t k = 0; k < trees_; ++k) vol_[std::size_t(k)] = treeVolumeOf(k);
    listThick();
    return it;
  }

  // A point from the stage's pdf in its terminal domain.
  Vec3 draw() {
    const auto& st = stage();
    const auto& d = *st.terminals;
    if (st.pdf != TerminalPdf::Gaussian) return d.sample(rng_);
    double total = 0;
    for (const auto& g : st.gaussians) total += g.weight;
    // prepare() refused mixtures with under a thousandth of their mass inside: a miss this many
    // times in a row is a region the Gaussians barely reach (a relaxation of nothing).
    for (std::int64_t misses = 0;; ++misses) {
      if (misses >= kGaussianMisses)
        throw GrowthError("stage '" + st.name + "': " + std::to_string(kGaussianMisses) +
                          " points drawn in a row from its Gaussians fell outside its terminal region; "
                          "move their means into it or widen them");
      double u = rng_.uniform() * total;
      const GaussianComponent* g = &st.gaussians.back();
      for (const auto& c : st.gaussians)
        if ((u -= c.weight) < 0) {
          g = &c;
          break;
        }
      Vec3 p = o_.world->center() + g->mean;
      p.x += g->sigma.x * rng_.normal();
      p.y += g->sigma.y * rng_.normal();
      if (d.dimension() == 3)
        p.z += g->sigma.z * rng_.normal();
      else
        p.z = d.planeZ();
      if (d.depth(p) > 0) return p;
    }
  }

  double limitLength() const {
    const int D = stage().terminals->dimension();
    return lc_ * std::pow(stage().nu / double(terminalCount() + 1), 1.0 / D);
  }

  // A distributing stage's root vessel lies inside the stage's domain (at depth r) from 2 r past
  // the root on. Depth changes by at most the distance moved, so a root more than r (and a
  // voxel of the region's map) outside that domain can never be joined: every draw would fail.
  void refuseRootOutsideItsStage() const {
    const auto& st = stage();
    if (st.role != VesselRole::Distribution || !st.vessels) return;
    const double r = kMargin * o_.root_radius;
    const double outside = -st.vessels->depth(o_.root_mm);
    if (outside <= r + st.vessels->frame().voxel_mm) return;
    throw GrowthError("stage '" + st.name + "': the root at (" + show(o_.root_mm.x) + ", " + show(o_.root_mm.y) + ", " + show(o_.root_mm.z) +
                      ") mm lies " + show(outside) + " mm outside the stage's domain, where its vessels must run; allowed: a root at most " +
                      show(r) + " mm (the root vessel's radius) outside it; move the root or widen the domain");
  }

  // Failed draws in a row before a stage gives up. After this many relaxations the spacing limit
  // is f_r^100 of itself (3e-5 at the usual 0.9, far below any vessel's radius): what still fails
  // is geometry that more draws do not change, and a hopeless stage is refused in a second.
  std::int64_t drawBudget() const {
    constexpr std::int64_t kRelaxationsBeforeGivingUp = 100;
    return std::min(o_.max_draws, kRelaxationsBeforeGivingUp * std::int64_t(stage().draws_before_relaxing));
  }

  // The root segment (Algorithm 2, line 1): a drawn point far enough from the root, with l > 2 r.
  void plantRoot() {
    double lim = limitLength();
    const auto& st = stage();
    refuseRootOutsideItsStage();
    const std::int64_t budget = drawBudget();
    for (std::int64_t draws = 1; draws <= budget; ++draws) {
      ++report_.candidates;
      const Vec3 p = draw();
      const double l = distance(o_.root_mm, p);
      // The root vessel brings the blood into the stage's domain: it stays in the world and,
      // when the stage distributes, inside the stage's domain from 2 r_1 past the root on (the
      // root may sit on the domain's border, where a rasterised region is inset by half a voxel).
      const double r = kMargin * o_.root_radius;
      const Vec3 from = o_.root_mm + (p - o_.root_mm) * (std::min(2 * r, l) / l);
      const bool inside =
          o_.world->capsuleInside(o_.root_mm, p, r, true) && (st.role != VesselRole::Distribution || st.vessels->capsuleInside(from, p, r, false));
      if (l > lim && l > 2 * kMargin * o_.root_radius && inside) {
        const auto n = t_.addNode(p, 0);
        t_.stage[n] = std::int16_t(stage_);
        t_.role[n] = std::uint8_t(st.role);
        t_.branching[n] = std::uint8_t(Branching::Versatile);
        t_.length[n] = l;
        eta_.push_back(o_.viscosity.at(o_.root_radius));
        t_.reduced_resistance[n] = e(n) * l;
        t_.cost_ratio[n] = l;
        rel_.push_back(1.0);
        checked_.push_back(o_.root_radius);
        load_.push_back(1.0);
        ++made_;
        solve();
        index_.refresh(t_, true);
        return;
      }
      ++report_.rejected_unreachable;
      if (draws % st.draws_before_relaxing == 0) {
        lim *= st.f_r;
        ++dr_.threshold_relaxations;
      }
    }
    throw GrowthError("stage '" + st.name +
                      "': no root vessel could be placed: every point drawn lies too close to the root, "
                      "makes a vessel shorter than twice the root radius or leaves the domain; move the root or enlarge the domain");
  }

  // Costs the trial point b on segment s for terminal x: fills t with the cost and the radii of the
  // three vessels that meet at the new junction, and `path` with the new values up to the root
  // (O(depth)). A distal trial hangs the new vessel from s's distal end (b = x_d) instead of
  // splitting s.
  void cost(std::int32_t s, const Vec3& b, const Vec3& x, Trial& tr, std::vector<Level>& path) const {
    const auto& T = t_;
    const std::int32_t q = T.parent[s];
    const double l_new = distance(b, x);
    const double es = e(s);
    const double R_t = es * l_new, V_t = l_new;
    path.clear();
    if (!tr.distal) {
      const double l_up = distance(T.position[q], b), l_down = distance(b, T.position[s]);
      const double R_sd = es * l_down + (T.reduced_resistance[s] - es * T.length[s]);
      const double V_sd = l_down + (T.cost_ratio[s] - T.length[s]);
      const auto sp = kernels_[stage_].split(load_[s], R_sd, 1, R_t, T.radius[s]);
      path.push_back(Level{-1, s, -1, sp.beta_a, sp.beta_b, es * l_up + 1.0 / (pow4(sp.beta_a) / R_sd + pow4(sp.beta_b) / R_t),
                           l_up + sp.beta_a * sp.beta_a * V_sd + sp.beta_b * sp.beta_b * V_t, T.terminals[s] + 1, load_[s] + 1});
    } else if (T.child0[s] < 0) {  // s ends free: the new vessel continues it, s stops being a terminal
      path.push_back(Level{s, -1, -1, 1, 1, es * T.length[s] + R_t, T.length[s] + V_t, T.terminals[s], load_[s]});
    } else {  // s's end becomes a bifurcation of its child and the new vessel
      const auto c = T.child0[s];
      const auto sp = kernels_[stage_].split(load_[c], T.reduced_resistance[c], 1, R_t, T.radius[s]);
      path.push_back(Level{s, c, -1, sp.beta_a, sp.beta_b,
                           es * T.length[s] + 1.0 / (pow4(sp.beta_a) / T.reduced_resistance[c] + pow4(sp.beta_b) / R_t),
                           T.length[s] + sp.beta_a * sp.beta_a * T.cost_ratio[c] + sp.beta_b * sp.beta_b * V_t, T.terminals[s] + 1, load_[s] + 1});
    }
    const std::int32_t dn = path[0].n - T.terminals[s];
    const double dw = path[0].w - load_[s];
    // Walk up: segment y = q ends at the node the level-0 segment hangs from.
    for (std::int32_t y = q; T.parent[y] >= 0; y = T.parent[y]) {
      const auto& below = path.back();
      const std::int32_t child = path.size() == 1 ? -1 : below.seg;  // -1: the level-0 segment
      const std::int32_t from = child < 0 ? s : child;
      const std::int32_t other = T.child0[y] == from ? T.child1[y] : T.child0[y];
      if (other < 0) {  // a continuation: the flow passes on
        path.push_back(Level{y, child, -1, 1, 0, e(y) * T.length[y] + below.R, T.length[y] + below.V, T.terminals[y] + dn, load_[y] + dw});
        continue;
      }
      const auto spl = kernelAt(T, y, kernels_).split(below.w, below.R, load_[other], T.reduced_resistance[other], T.radius[y]);
      path.push_back(Level{y, child, other, spl.beta_a, spl.beta_b,
                           e(y) * T.length[y] + 1.0 / (pow4(spl.beta_a) / below.R + pow4(spl.beta_b) / T.reduced_resistance[other]),
                           T.length[y] + spl.beta_a * spl.beta_a * below.V + spl.beta_b * spl.beta_b * T.cost_ratio[other], T.terminals[y] + dn,
                           load_[y] + dw});
    }
    double rho = 1;
    for (std::size_t k = path.size(); k-- > 1;) rho *= path[k].beta_child;
    const double r1 = rootRadiusOf(s);
    const double rb = r1 * rho;
    tr.r[0] = rb;
    if (!tr.distal) {
      tr.r[1] = rb * path[0].beta_child;
      tr.r[2] = rb * path[0].beta_other;
    } else {
      tr.r[1] = T.child0[s] < 0 ? 0.0 : rb * path[0].beta_child;
      tr.r[2] = rb * path[0].beta_other;
    }
    const double volume_after = std::numbers::pi * r1 * r1 * path.back().V;
    const double added = volume_after - vol_[std::size_t(T.tree[s])];
    const auto& st = stage();
    if (st.cost == StageCost::Volume) {
      tr.cost = added;
    } else {  // eq. 15: V_ref the stage's domain measure, l_ref its l_c, r_ref the root radius
      const double l = l_new / lc_;
      tr.cost = st.c_v * added / st.vessels->measure() + st.c_p * radiusOf(s) / o_.root_radius + st.c_d * l * l;
    }
  }

  // The checks of a trial point that need no other vessel (run in parallel).
  bool admissible(std::int32_t s, const Vec3& b, const Vec3& x, const Trial& tr, int level) const {
    const auto& T = t_;
    const auto& st = stage();
    if (tr.distal) {
      // Only the new vessel is made; a bifurcation it forms with s's child must be symmetric enough.
      if (!(distance(b, x) > 2 * kMargin * tr.r[2])) return false;
      if (tr.r[1] > 0 && !(std::min(tr.r[1], tr.r[2]) / std::max(tr.r[1], tr.r[2]) > st.deltaAt(level))) return false;
      if (VesselRole(T.role[s]) == VesselRole::Perforator && !(st.vessels->depth(b) > 0)) return false;
      return st.role != VesselRole::Distribution || st.vessels->depth(b) >= kMargin * tr.r[2];
    }
    const Vec3 xp = T.position[T.parent[s]], xd = T.position[s];
    const double l[3] = {distance(xp, b), distance(b, xd), distance(b, x)};
    for (int k = 0; k < 3; ++k)
      if (!(l[k] > 2 * kMargin * tr.r[k])) return false;
    const double ratio = std::min(tr.r[1], tr.r[2]) / std::max(tr.r[1], tr.r[2]);
    if (!(ratio > st.deltaAt(level))) return false;
    const auto br = Branching(T.branching[s]);
    if (br != Branching::Distal) {  // a distal branch continues the vessel's end: no angle to keep
      const double th = bifurcationAngle(b, xd, x);
      if (th < st.theta_min || th > st.theta_max) return false;
      Vec3 fallback;
      if (T.parent[T.parent[s]] >= 0) {  // the plane of the bifurcation s leaves
        const auto q = T.parent[s];
        const auto sib = T.sibling(s);
        if (sib >= 0) fallback = cross(T.position[q] - T.position[T.parent[q]], T.position[sib] - T.position[q]);
      }
      const double ph = openingAngle(xp, b, xd, x, fallback);
      if (ph < st.phi_min || ph > st.phi_max) return false;
    }
    // A perforator branches only inside Ω.
    if (VesselRole(T.role[s]) == VesselRole::Perforator && !(st.vessels->depth(b) > 0)) return false;
    // The bifurcation point where its vessels may lie (contained() checks their whole capsules).
    if (st.role == VesselRole::Distribution && !(st.vessels->depth(b) >= kMargin * tr.r[2])) return false;
    if (VesselRole(T.role[s]) == VesselRole::Distribution && T.stage[s] >= 0 && !(o_.stages[T.stage[s]].vessels->depth(b) >= kMargin * tr.r[1]))
      return false;
    // A vessel of the initial network is split only inside the world.
    if (T.stage[s] < 0 && !(o_.world->depth(b) >= 0)) return false;
    return true;
  }

  // Where the roles let the vessels lie: the new vessel (the stage's role) inside the stage's
  // domain if it distributes, else in the world; the two parts of the split vessel keep its role
  // and stage, so a distribution vessel's parts stay in the domain of the stage that made it or
  // of the current stage (the root vessel, which brings the blood in, and other roles only in
  // the world). Every vessel stays in the world (a rasterised region may overhang it by half a
  // voxel). Checked on the cheapest trials only (a mask domain samples every ¼ voxel).
  bool contained(const Trial& tr, const Vec3& x) const {
    const auto& T = t_;
    const auto s = tr.s;
    const Vec3 xp = T.position[T.parent[s]], xd = T.position[s];
    const double r[3] = {kMargin * tr.r[0], kMargin * tr.r[1], kMargin * tr.r[2]};
    if (tr.distal) return vesselFits(tr.b, x, r[2], false, stage().role, stage_);
    return vesselFits(tr.b, x, r[2], false, stage().role, stage_) && segmentFits(s, xp, tr.b, r[0]) &&
           vesselFits(tr.b, xd, r[1], false, VesselRole(T.role[s]), T.stage[s]);
  }

  // vesselFits for (a new course of) existing segment x: the root vessel only in the world; the
  // initial network's vessels (and their parts) where they are.
  bool segmentFits(std::int32_t x, const Vec3& a, const Vec3& e, double r) const {
    if (t_.stage[x] < 0 && given_ > 0) return true;
    const bool root_seg = t_.parent[t_.parent[x]] < 0;
    return vesselFits(a, e, r, root_seg, root_seg ? VesselRole::Transport : VesselRole(t_.role[x]), t_.stage[x]);
  }

  // True if the capsule a–e of radius r, of a vessel with this role made by stage `made`, lies
  // where it may: in the world, and a distribution vessel also in its stage's or the current
  // stage's domain.
  bool vesselFits(const Vec3& a, const Vec3& e, double r, bool from_root, VesselRole role, int made) const {
    if (made < 0 && given_ > 0) return true;
    if (!o_.world->capsuleInside(a, e, r, from_root)) return false;
    if (role != VesselRole::Distribution || made < 0) return true;
    const auto* own = o_.stages[made].vessels;
    const auto* now = stage().vessels;
    return (own != o_.world && own->capsuleInside(a, e, r, from_root)) || own == o_.world ||
           (now != own && (now == o_.world || now->capsuleInside(a, e, r, from_root)));
  }

  // True if the capsule a–e (radius r) of segment x overlaps a vessel more than two segments
  // away, or if its centreline runs through one of its near neighbours (one segment between
  // them: their capsules may touch at the joint, their centrelines may not come within half
  // the thinner radius; the lattice's bifurcation points can fold a branch over its sibling).
  bool overlaps(std::int32_t x, const Vec3& a, const Vec3& e, double r) {
    return hitsVessel(
        a, e, r,
        [&](std::int32_t y) {
          return y == x || sharesNode(x, y) ? Neighbour::Meets : withinTwoSegments(t_, x, y) ? Neighbour::Near : Neighbour::Apart;
        },
        [&](std::int32_t y, double reach) { return joinedAlongVessel(t_, x, y, reach); });
  }

  enum class Neighbour { Meets, Near, Apart };
  // True if the capsule a–e of radius r overlaps a vessel y that `kind(y)` calls Apart, or runs
  // its centreline within half the thinner radius of one it calls Near (Meets: exempt). An Apart
  // vessel that `along(y, reach)` finds within reach along the same vessel (the pieces of a
  // polyline in an initial network) is held to the Near rule. The grid as far as thin vessels
  // reach; the few thick ones from their list, so the search does not widen with the root radius.
  template <class Kind, class Along>
  bool hitsVessel(const Vec3& a, const Vec3& e, double r, Kind&& kind, Along&& along) {
    bool hit = false;
    const auto test = [&](std::int32_t y) {
      // A link lies inside the cap of the vessel that ends at its junction: that vessel stands for it.
      if (hit || y >= t_.nodeCount() || t_.parent[y] < 0 || t_.isLink(y)) return;
      const auto k = kind(y);
      if (k == Neighbour::Meets) return;
      // Vessels that meet at an N-ary junction share its point, with links between them.
      const Vec3 &ya = t_.position[t_.parent[y]], &ye = t_.position[y];
      if (ya == a || ya == e || ye == a || ye == e) return;
      const double d = segmentSegmentDistance(a, e, t_.position[t_.parent[y]], t_.position[y]);
      const double ry = kMargin * radiusOf(y);
      hit = k == Neighbour::Near || (d < r + ry && along(y, r + ry)) ? d < 0.5 * std::min(r, ry) : d < r + ry;
    };
    index_.forEachNearSegment(a, e, r + kMargin * kThickReach * o_.root_radius, test);
    for (auto y : thick_)
      if (!hit && y < t_.nodeCount() && radiusOf(y) > kThickReach * o_.root_radius) test(y);
    return hit;
  }
  // Segments with ρ above kThickList, listed at each fixed point and when made.
  void listThick() {
    thick_.clear();
    for (std::int32_t i = 1; i < t_.nodeCount(); ++i)
      if (t_.parent[i] >= 0 && rel_[i] >= kThickList) thick_.push_back(i);
  }
  // True if segments x and y meet at a node (an N-ary junction's nodes count as one).
  bool sharesNode(std::int32_t x, std::int32_t y) const {
    const auto px = t_.junction(t_.parent[x]), py = t_.junction(t_.parent[y]);
    return px == py || px == t_.junction(y) || py == t_.junction(x);
  }

  // The three new vessels of a trial against the tree before it is committed, each with the
  // neighbours it will have (sharing a node: exempt; one segment between: the rule for near
  // neighbours; s itself is replaced). A cheap filter before the exact check after commit.
  bool trialHits(const Trial& tr, const Vec3& x) {
    const auto s = tr.s, q = t_.parent[s];
    const auto& T = t_;
    // Where b lies on s: its distances to s's proximal and distal node.
    const double to_prox = distance(tr.b, T.position[q]), to_dist = distance(tr.b, T.position[s]);
    const std::int32_t sib = T.sibling(s), c0 = T.child0[s], c1 = T.child1[s];
    const auto kids = [&](std::int32_t y, std::int32_t* out, int& n) {
      if (y > 0 && T.child0[y] >= 0) out[n++] = T.child0[y];
      if (y > 0 && T.child1[y] >= 0) out[n++] = T.child1[y];
    };
    if (tr.distal) {  // the new vessel x_d→x: shares x_d with s and its child; next to s's parent and sibling, its grandchildren
      const std::int32_t share[2] = {c0, c1};
      std::int32_t near[6] = {T.parent[q] >= 0 ? q : -1, sib};
      int n = 2;
      kids(c0, near, n);
      return capsuleHits(tr.b, x, kMargin * tr.r[2], s, {share, share + 2}, {near, near + n}, to_prox, to_dist);
    }
    // The new vessel b→x: next to s's parent and sibling (through the proximal part) and s's children.
    {
      const std::int32_t near[4] = {q, sib, c0, c1};
      if (capsuleHits(tr.b, x, kMargin * tr.r[2], s, {}, {near, near + 4}, to_prox, to_dist)) return true;
    }
    // The distal part b→xd: shares xd with s's children; next to s's parent, sibling, grandchildren.
    {
      const std::int32_t share[2] = {c0, c1};
      std::int32_t near[6] = {q, sib};
      int n = 2;
      kids(c0, near, n);
      kids(c1, near, n);
      if (capsuleHits(tr.b, T.position[s], kMargin * tr.r[1], s, {share, share + 2}, {near, near + n}, to_prox, 0)) return true;
    }
    // The proximal part q→b: shares q with s's parent and sibling; next to their neighbours and s's children.
    {
      const std::int32_t share[2] = {q, sib};
      std::int32_t near[7] = {c0, c1};
      int n = 2;
      if (q > 0 && T.parent[q] >= 0) {
        near[n++] = T.parent[q] > 0 && T.parent[T.parent[q]] >= 0 ? T.parent[q] : -1;
        near[n++] = T.parent[T.parent[q]] >= 0 ? T.sibling(q) : -1;
      }
      kids(sib, near, n);
      if (capsuleHits(T.position[q], tr.b, kMargin * tr.r[0], s, {share, share + 2}, {near, near + n}, 0, to_dist)) return true;
    }
    return false;
  }

  // True if the capsule a–e of radius r overlaps a vessel other than `skip` and `share` (which
  // meet it), with `near` (one segment away) held only to the rule for near neighbours.
  bool capsuleHits(const Vec3& a, const Vec3& e, double r, std::int32_t skip, std::span<const std::int32_t> share, std::span<const std::int32_t> near,
                   double from_prox, double from_dist) {
    const auto in = [](std::span<const std::int32_t> list, std::int32_t y) { return std::find(list.begin(), list.end(), y) != list.end(); };
    return hitsVessel(
        a, e, r, [&](std::int32_t y) { return y == skip || in(share, y) ? Neighbour::Meets
                                              : in(near, y)             ? Neighbour::Near
                                                                        : Neighbour::Apart; },
        [&](std::int32_t y, double reach) { return joinedAlongVessel(t_, skip, y, reach, from_prox, from_dist); });
  }

  // The vessels of the last commit (proximal part, distal part s, new vessel) against the tree.
  bool newVesselsCollide(const Trial& tr) {
    const auto s = tr.s;
    if (tr.distal) {  // the new vessel, s and its other child (both thickened)
      const auto n = t_.nodeCount() - 1;
      for (const std::int32_t x : {n, s, t_.child0[s] == n ? -1 : t_.child0[s]})
        if (x > 0 && overlaps(x, t_.position[t_.parent[x]], t_.position[x], kMargin * radiusOf(x))) return true;
      return false;
    }
    const auto b = t_.nodeCount() - 2;
    // s's children too: the new bifurcation puts a segment more between them and s's old
    // neighbours, which may now touch them only where the rule for near neighbours allows.
    for (const std::int32_t x : {std::int32_t(b + 1), b, s, t_.child0[s], t_.child1[s]})
      if (x > 0 && overlaps(x, t_.position[t_.parent[x]], t_.position[x], kMargin * radiusOf(x))) return true;
    return false;
  }

  struct Saved {
    std::int32_t id, n;
    double R, V, beta, rel, w;
  };

  // Applies a costed trial (path recorded by cost()).
  void commit(const Trial& tr, const Vec3& x, const std::vector<Level>& path, std::vector<Saved>& undo) {
    auto& T = t_;
    const auto s = tr.s, q = T.parent[s];
    undo.clear();
    const auto save = [&](std::int32_t id) {
      if (id >= 0) undo.push_back({id, T.terminals[id], T.reduced_resistance[id], T.cost_ratio[id], T.beta[id], rel_[id], load_[id]});
    };
    save(s);
    if (tr.distal) save(T.child0[s]);
    for (std::size_t k = 1; k < path.size(); ++k) {
      save(path[k].seg);
      save(path[k].other);
    }
    const double es = e(s);
    std::int32_t b = s;  // the level-0 segment
    if (!tr.distal) {
      b = T.addNode(tr.b, -1);
      T.parent[b] = q;
      T.tree[b] = T.tree[q];
      T.replaceChild(q, s, b);
      T.parent[s] = b;
      T.child0[b] = s;
      T.stage[b] = T.stage[s];  // the proximal part of the split vessel
      T.role[b] = T.role[s];
      T.branching[b] = T.branching[s];
      T.length[b] = distance(T.position[q], tr.b);
      const double l_down = distance(tr.b, T.position[s]);
      T.reduced_resistance[s] = es * l_down + (T.reduced_resistance[s] - es * T.length[s]);
      T.cost_ratio[s] = l_down + (T.cost_ratio[s] - T.length[s]);
      T.length[s] = l_down;
      eta_.push_back(eta_[s]);
    }
    const auto n = T.addNode(x, b);
    T.stage[n] = std::int16_t(stage_);
    T.role[n] = std::uint8_t(stage().role);
    T.branching[n] = std::uint8_t(Branching::Versatile);
    eta_.push_back(eta_[s]);
    T.reduced_resistance[n] = es * T.length[n];
    T.cost_ratio[n] = T.length[n];
    T.terminals[n] = 1;
    ++made_;
    rel_.resize(T.nodeCount());
    checked_.resize(T.nodeCount(), 0.0);
    load_.resize(T.nodeCount(), 0.0);
    load_[n] = 1;
    for (std::size_t k = 0; k < path.size(); ++k) {
      const auto& L = path[k];
      const auto seg = k == 0 ? b : L.seg;
      const auto child = k == 0 ? (tr.distal ? L.child : s) : (k == 1 ? b : L.child);
      const auto other = k == 0 ? n : L.other;
      T.terminals[seg] = L.n;
      load_[seg] = L.w;
      T.reduced_resistance[seg] = L.R;
      T.cost_ratio[seg] = L.V;
      if (child >= 0) T.beta[child] = L.beta_child;
      if (other >= 0) T.beta[other] = L.beta_other;
    }
    const auto top = path.size() == 1 ? b : path.back().seg;
    T.beta[top] = 1;
    rel_[top] = 1;
    for (std::size_t k = path.size(); k-- > 0;) {
      const auto& L = path[k];
      const auto seg = k == 0 ? b : L.seg;
      const auto child = k == 0 ? (tr.distal ? L.child : s) : (k == 1 ? b : L.child);
      const auto other = k == 0 ? n : L.other;
      if (child >= 0) rel_[child] = rel_[seg] * L.beta_child;
      if (other >= 0) rel_[other] = rel_[seg] * L.beta_other;
    }
    vol_[std::size_t(T.tree[s])] = treeVolumeOf(T.tree[s]);
    // In the index before the checks, taken back by a rollback; s's distal part keeps its old
    // entries too (they are harmless: queries measure the current geometry).
    index_.beginTrial();
    if (!tr.distal) index_.insert(T, b);
    index_.insert(T, n);
    index_.insert(T, s);
    listed_thick_ = !tr.distal && rel_[b] >= kThickList;
    if (listed_thick_) thick_.push_back(b);
  }

  void rollback(const Trial& tr, const std::vector<Saved>& undo) {
    auto& T = t_;
    const auto n = T.nodeCount() - 1;
    std::int32_t cut = n;
    if (tr.distal) {
      const auto s = T.parent[n];
      if (T.child1[s] == n)
        T.child1[s] = -1;
      else
        T.child0[s] = -1;
    } else {
      const auto b = n - 1;
      const auto s = T.child0[b], q = T.parent[b];
      T.replaceChild(q, b, s);
      T.parent[s] = q;
      T.length[s] = distance(T.position[q], T.position[s]);
      cut = b;
    }
    index_.endTrial(false);
    if (listed_thick_) thick_.pop_back();
    T.truncate(cut);
    eta_.resize(cut);
    rel_.resize(cut);
    checked_.resize(cut);
    load_.resize(cut);
    --made_;
    for (auto it = undo.rbegin(); it != undo.rend(); ++it) {
      T.terminals[it->id] = it->n;
      T.reduced_resistance[it->id] = it->R;
      T.cost_ratio[it->id] = it->V;
      T.beta[it->id] = it->beta;
      rel_[it->id] = it->rel;
      load_[it->id] = it->w;
    }
    vol_[std::size_t(T.tree[tr.s])] = treeVolumeOf(T.tree[tr.s]);
  }

  // After a commit: the ancestors that thickened past kRecheckGrowth since last found clear.
  bool ancestorsCollide(const std::vector<Level>& path) {
    for (std::size_t k = 1; k < path.size(); ++k) {
      const auto x = path[k].seg;
      const double r = radiusOf(x);
      if (r <= kRecheckGrowth * checked_[x]) continue;
      if (overlaps(x, t_.position[t_.parent[x]], t_.position[x], kMargin * r)) return true;
      checked_[x] = r;
    }
    return false;
  }

  // True if vessel y may take a new branch: not a non-branching vessel or an outlet (its flow
  // is prescribed), and a distal one only while its end has fewer than two children.
  bool mayBranch(std::int32_t y) const {
    const auto b = Branching(t_.branching[y]);
    if (b == Branching::None || b == Branching::Unset || t_.outflow[y] > 0) return false;
    return b != Branching::Distal || t_.child1[y] < 0;
  }

  // Connects terminal x to the cheapest admissible point of its candidate vessels; false if none.
  bool connect(const Vec3& x) {
    const auto& st = stage();
    // VItA's box: f_n times the unrelaxed l_lim, so that relaxing the spacing does not shrink it.
    const double half = st.f_n * limitLength();
    near_.clear();
    const Vec3 h(half, half, st.terminals->dimension() == 2 ? 0.0 : half);
    index_.forEachInBox(x - h, x + h, [&](std::int32_t y) {
      if (y <= 0 || y >= t_.nodeCount() || t_.parent[y] < 0 || !mayBranch(y)) return;
      const Vec3 a = t_.position[t_.parent[y]], e = t_.position[y];
      // The vessel's point nearest to x must lie in the box.
      const Vec3 ab = e - a;
      const double u = std::clamp(dot(x - a, ab) / std::max(dot(ab, ab), 1e-300), 0.0, 1.0);
      const Vec3 c = a + ab * u - x;
      if (std::abs(c.x) <= half && std::abs(c.y) <= half && std::abs(c.z) <= half) near_.push_back({norm(c), y});
    });
    std::sort(near_.begin(), near_.end());
    if (near_.size() > std::size_t(st.max_candidates)) near_.resize(st.max_candidates);
    if (near_.empty()) return false;
    // Cost every lattice point of every candidate (in parallel; the tree is read only).
    const std::size_t nc = near_.size();
    trials_.assign(nc, {});
    counts_.assign(nc, 0);
    const auto evaluate = [&](std::size_t c) {
      const auto s = near_[c].second;
      const auto pts = bifurcationLattice(x, t_.position[t_.parent[s]], t_.position[s], st.delta_v, Branching(t_.branching[s]));
      int level = -1;  // bifurcation level of the proximal part: bifurcations above it (links are no level)
      for (std::int32_t y = t_.parent[s]; t_.parent[y] >= 0; y = t_.parent[y]) level += !t_.isLink(y);
      std::vector<Level> path;
      auto& out = trials_[c];
      counts_[c] = pts.size();
      out.reserve(pts.size());
      for (const auto& b : pts) {
        Trial tr;
        tr.s = s;
        tr.b = b;
        tr.distal = Branching(t_.branching[s]) == Branching::Distal;
        cost(s, b, x, tr, path);
        tr.valid = admissible(s, b, x, tr, level + 1);
        if (tr.valid) out.push_back(tr);
      }
    };
    if (nc >= 4)
      tbb::parallel_for(std::size_t(0), nc, evaluate);
    else
      for (std::size_t c = 0; c < nc; ++c) evaluate(c);
    ranked_.clear();
    for (std::size_t c = 0; c < nc; ++c) {
      dr_.trial_points += std::int64_t(counts_[c]);
      for (const auto& tr : trials_[c]) ranked_.push_back(tr);
    }
    // Cheapest first; ties by segment and point order (deterministic for any thread count).
    std::stable_sort(ranked_.begin(), ranked_.end(), [](const Trial& a, const Trial& b) { return a.cost < b.cost; });
    std::vector<Level> path;
    for (const auto& tr : ranked_) {
      if (!contained(tr, x)) continue;
      if (trialHits(tr, x)) {
        ++report_.rejected_intersection;
        continue;
      }
      // Committed first, so that the overlap checks see the new vessels' true neighbours.
      Trial exact = tr;
      cost(tr.s, tr.b, x, exact, path);
      commit(exact, x, path, undo_);
      if (newVesselsCollide(tr)) {
        rollback(tr, undo_);
        ++report_.rejected_intersection;
        continue;
      }
      if (ancestorsCollide(path)) {
        rollback(tr, undo_);
        ++report_.rejected_intersection;
        continue;
      }
      const auto n = t_.nodeCount() - 1;
      if (!tr.distal) checked_[n - 1] = radiusOf(n - 1);
      checked_[n] = radiusOf(n);
      checked_[tr.s] = radiusOf(tr.s);
      index_.endTrial(true);
      index_.refresh(t_);
      if (double(t_.nodeCount()) > (1 + kRefreshShare) * double(solved_at_)) solve();
      return true;
    }
    return false;
  }

  void growStage(const ProgressFn& progress, std::int64_t total) {
    const auto& st = stage();
    std::int64_t next_report = 0;
    if (t_.nodeCount() < 2) plantRoot();
    while (made_ < st.terminal_count) {
      if (progress && terminalCount() >= next_report) {
        progress(terminalCount(), total);
        next_report = terminalCount() + std::max<std::int64_t>(1, total / 200);
      }
      double lim = limitLength();
      const std::int64_t budget = drawBudget();
      for (std::int64_t failures = 1;; ++failures) {
        if (failures > budget)
          throw GrowthError("stage '" + st.name + "' placed " + std::to_string(made_) + " of its " + std::to_string(st.terminal_count) +
                            " terminals: " + std::to_string(budget) +
                            " points in a row found no admissible connection; lower its terminals, relax its angle or symmetry limits, "
                            "or enlarge its domain");
        const Vec3 x = draw();
        if (index_.anyWithin(t_, x, lim)) {
          ++report_.rejected_too_close;
        } else {
          ++report_.candidates;
          if (connect(x)) break;
          ++report_.rejected_unreachable;
        }
        if (failures % st.draws_before_relaxing == 0) {
          lim *= st.f_r;
          ++dr_.threshold_relaxations;
        }
      }
    }
  }

  // Segments of the solved tree that break a constraint, each as the segment whose subtree goes:
  // intersecting pairs, length <= 2r, leaving the world, terminal bifurcations below their δ.
  std::vector<std::int32_t> violations(bool fix) {
    std::vector<std::int32_t> out;
    const auto& T = t_;
    const auto pick = [&](std::int32_t a, std::int32_t b) { return T.terminals[a] <= T.terminals[b] ? a : b; };
    const auto pairs = intersectingPairs(T, o_.world->lo(), o_.world->hi());
    report_.intersecting_pairs = std::int64_t(pairs.size());
    for (const auto& [x, y] : pairs) {
      if (T.stage[x] < 0 && T.stage[y] < 0 && given_ > 0) {  // the initial network as it was given
        --report_.intersecting_pairs;
        continue;
      }
      // Pieces of one vessel of the initial network, and a branch off it, within reach along it
      // (the rule growth held them to).
      if (given_ > 0 && joinedAlongVessel(T, x, y, kMargin * (T.radius[x] + T.radius[y]))) {
        --report_.intersecting_pairs;
        continue;
      }
      // The vessel of this stage whose subtree holds fewer terminals goes.
      const bool ox = ownSubtree(x), oy = ownSubtree(y);
      out.push_back(ox && oy ? pick(x, y) : ox ? x : y);
    }
    dr_.short_segments = dr_.outside_segments = dr_.asymmetric_bifurcations = dr_.folded_pairs = 0;
    index_.refresh(t_, true);
    const double r_max = *std::max_element(r1_.begin(), r1_.end());
    for (std::int32_t x = 1; x < T.nodeCount(); ++x) {
      if (T.parent[x] < 0) continue;
      const Vec3 a = T.position[T.parent[x]], e = T.position[x];
      if (T.isLink(x)) continue;
      index_.forEachNearSegment(a, e, T.radius[x] + r_max, [&](std::int32_t y) {
        if (y <= x || y >= T.nodeCount() || T.parent[y] < 0 || T.isLink(y) || sharesNode(x, y) || !withinTwoSegments(T, x, y)) return;
        if (T.stage[x] < 0 && T.stage[y] < 0 && given_ > 0) return;
        if (segmentSegmentDistance(a, e, T.position[T.parent[y]], T.position[y]) < 0.5 * std::min(T.radius[x], T.radius[y])) {
          ++dr_.folded_pairs;
          const bool ox = ownSubtree(x), oy = ownSubtree(y);
          out.push_back(ox && oy ? pick(x, y) : ox ? x : y);
        }
      });
    }
    for (std::int32_t s = 1; s < T.nodeCount(); ++s) {
      if (T.isRoot(s) || T.isLink(s)) continue;
      if (!(T.length[s] > 2 * T.radius[s]) && !(fix && lengthen(s))) {
        ++dr_.short_segments;
        const auto a = T.child0[s], b = T.child1[s];
        if (b < 0)
          out.push_back(a >= 0 && ownSubtree(a) ? a : s);
        else
          out.push_back(T.isTerminal(s) || !(ownSubtree(a) || ownSubtree(b)) ? s : pick(a, b));
      }
      if (!segmentFits(s, T.position[T.parent[s]], T.position[s], T.radius[s])) {
        ++dr_.outside_segments;
        out.push_back(s);
      }
      const auto a = T.child0[s], b = T.child1[s];
      if (a >= 0 && b >= 0 && T.isTerminal(a) && T.isTerminal(b) && T.stage[b] >= 0) {
        const auto& st = o_.stages[T.stage[b]];
        const double ratio = std::min(T.radius[a], T.radius[b]) / std::max(T.radius[a], T.radius[b]);
        if (!(ratio > st.deltaAt(T.depth[s] - 1))) {
          ++dr_.asymmetric_bifurcations;
          out.push_back(b);
        }
      }
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  // A vessel that later stages thickened past half its length: its distal bifurcation slides
  // along it (or its proximal one back) to 2.1–3 r, if every vessel meeting there still fits
  // (in place, with the solved radii).
  bool lengthen(std::int32_t s) {
    auto& T = t_;
    if (T.isTerminal(s)) return false;
    const auto P = T.parent[s];
    const Vec3 a = T.position[P], e = T.position[s];
    const Vec3 u = (e - a) / distance(a, e);
    for (double f : {2.1, 2.5, 3.0}) {
      const double L = f * T.radius[s];
      if (tryMove(s, a + u * L)) return true;
      if (T.parent[P] >= 0 && T.parent[T.parent[P]] >= 0 && tryMove(P, e - u * L)) return true;
    }
    return false;
  }

  // Moves node v to q if the vessels meeting there stay longer than 2 r, where their roles allow
  // and clear of every other vessel; restores it otherwise.
  bool tryMove(std::int32_t v, const Vec3& q) {
    auto& T = t_;
    if (givenNode(v)) return false;  // the initial network keeps its geometry
    const Vec3 old = T.position[v];
    T.position[v] = q;
    const std::int32_t segs[3] = {v, T.child0[v], T.child1[v]};
    bool ok = true;
    for (auto x : segs) {
      if (x <= 0 || !ok) continue;
      const Vec3 a = T.position[T.parent[x]], e = T.position[x];
      ok = distance(a, e) > 2 * kMargin * T.radius[x] && segmentFits(x, a, e, T.radius[x]) && !overlaps(x, a, e, kMargin * T.radius[x]);
    }
    if (!ok) {
      T.position[v] = old;
      return false;
    }
    for (auto x : segs)
      if (x > 0) {
        T.length[x] = distance(T.position[T.parent[x]], T.position[x]);
        index_.insert(T, x);
      }
    ++moved_;
    ++report_.moved_nodes;
    return true;
  }

  // True if every vessel of segment s's subtree was made by the current stage.
  bool ownSubtree(std::int32_t s) const {
    std::vector<std::int32_t> stack{s};
    while (!stack.empty()) {
      const auto i = stack.back();
      stack.pop_back();
      if (t_.stage[i] != stage_) return false;
      if (t_.child0[i] >= 0) stack.push_back(t_.child0[i]);
      if (t_.child1[i] >= 0) stack.push_back(t_.child1[i]);
    }
    return true;
  }

  // The top-most segments below s whose subtrees this stage made alone.
  void ownBranchesBelow(std::int32_t s, std::vector<std::int32_t>& out) const {
    std::vector<std::int32_t> stack;
    for (auto c : {t_.child0[s], t_.child1[s]})
      if (c >= 0) stack.push_back(c);
    while (!stack.empty()) {
      const auto i = stack.back();
      stack.pop_back();
      if (ownSubtree(i)) {
        out.push_back(i);
        continue;
      }
      if (t_.child0[i] >= 0) stack.push_back(t_.child0[i]);
      if (t_.child1[i] >= 0) stack.push_back(t_.child1[i]);
    }
  }

  // The stage's exact tree is checked; vessels of this stage that break a constraint are removed
  // and regrown in the stage, until none is left (older vessels are never removed).
  void repairStage(const ProgressFn& progress, std::int64_t total) {
    for (int round = 0;; ++round) {
      solve();
      const auto moved = moved_;
      auto bad = violations(true);
      // A vessel of an earlier stage that thickened into a neighbour (or below 2 r) sheds the
      // branches this stage hung below it: they regrow elsewhere, and its radius falls back.
      std::vector<std::int32_t> fix;
      // At most kMaxShedShare of the stage's terminals per vessel (a trunk of an earlier stage may
      // carry the whole stage), doubled while that leaves a violation with nothing to shed.
      for (double cap = kMaxShedShare;; cap = std::min(1.0, 2 * cap)) {
        fix.clear();
        bool held = false;
        for (auto s : bad) {
          if (ownSubtree(s)) {
            fix.push_back(s);
            continue;
          }
          std::vector<std::int32_t> below;
          ownBranchesBelow(s, below);
          std::int64_t shed = 0;
          for (auto b : below) shed += t_.terminals[b];
          if (double(shed) <= std::max(1.0, cap * double(stage().terminal_count)))
            fix.insert(fix.end(), below.begin(), below.end());
          else
            held = true;
        }
        if (!fix.empty() || !held || cap >= 1) break;
      }
      std::sort(fix.begin(), fix.end());
      fix.erase(std::unique(fix.begin(), fix.end()), fix.end());
      bad = fix;
      if (bad.empty() && moved_ > moved && round < o_.max_repair_rounds) continue;  // nodes moved: solve and check again
      if (bad.empty() || round == o_.max_repair_rounds) break;
      ++report_.repair_rounds;
      const auto n = terminalCount();
      t_.removeSubtrees(bad);
      report_.repaired_terminals += n - terminalCount();
      eta_.assign(t_.nodeCount(), o_.viscosity.at(o_.root_radius));
      solve();
      made_ = stageTerminals();
      checked_ = t_.radius;
      index_.refresh(t_, true);
      growStage(progress, total);
    }
  }

  void finalCounts() {
    violations(false);
    dr_.volume_mm3 = treeVolume(t_);
    report_.root_radius_mm = o_.root_radius;
  }

  const DccoOptions& o_;
  GrowthReport& report_;
  DccoReport& dr_;
  Rng rng_;
  VascularTree t_;
  SegmentIndex index_;
  std::vector<double> eta_, rel_, checked_, gamma_;
  std::vector<std::int32_t> thick_;
  bool listed_thick_ = false;  // the last commit appended its proximal part to thick_
  std::int64_t moved_ = 0;
  std::vector<PowerKernel> kernels_;
  int stage_ = 0;
  double lc_ = 1;
  std::vector<double> vol_, r1_, load_;  // per tree: volume, root radius; per segment: load (Level::w)
  std::vector<std::int32_t> rootOf_;     // per tree: its root node
  std::int32_t trees_ = 1, given_ = 0;   // trees; nodes of the initial network
  std::int64_t made_ = 0;                // terminals the current stage made
  std::int32_t solved_at_ = 0;
  std::vector<std::pair<double, std::int32_t>> near_;
  std::vector<std::vector<Trial>> trials_;
  std::vector<Trial> ranked_;
  std::vector<std::size_t> counts_;
  std::vector<Saved> undo_;
};

}  // namespace

int solveDccoTree(VascularTree& t, std::vector<double>& eta, const DccoOptions& o, const std::vector<double>& gamma_of_stage,
                  const std::vector<double>& root_radius, std::vector<double>* load_out, double tolerance) {
  if (t.nodeCount() < 2) return 0;
  const auto order = t.topDownOrder();
  eta.resize(t.nodeCount(), o.viscosity.at(o.root_radius));
  std::vector<double> next;
  std::vector<double> own_load;
  auto& load = load_out ? *load_out : own_load;
  load.assign(t.nodeCount(), 0.0);
  const auto kernels = kernelsOf(gamma_of_stage, o);
  // Banded γ: each bifurcation's from its parent's radius of the pass before, to a fixed point
  // with the viscosities.
  const bool banded = kernels.front().law().banded();
  std::vector<double> radius_used;
  // Outlets carry f_i·Q; the common terminals share (1 − Σf)·Q: in units of their flow q_f an
  // outlet weighs f_i·N_common / (1 − Σf).
  std::int64_t common = 0;
  double reserved = 0;
  for (std::int32_t i = 0; i < t.nodeCount(); ++i)
    if (t.isTerminal(i)) {
      if (t.outflow[i] > 0)
        reserved += t.outflow[i];
      else
        ++common;
    }
  if (common == 0) throw GrowthError("every terminal of the tree has a prescribed outflow: none is left to perfuse the domain");
  const auto outletLoad = [&](std::int32_t i) { return t.outflow[i] * double(common) / (1 - reserved); };
  int it = 0;
  for (;;) {
    ++it;
    if (banded) radius_used = t.radius;
    for (auto k = order.rbegin(); k != order.rend(); ++k) {
      const auto i = *k;
      if (t.parent[i] < 0) continue;
      t.length[i] = distance(t.position[t.parent[i]], t.position[i]);
      const double ei = eta[i] / kEtaRef;
      const auto a = t.child0[i], b = t.child1[i];
      if (a < 0) {
        t.terminals[i] = 1;
        load[i] = t.outflow[i] > 0 ? outletLoad(i) : 1.0;
        t.reduced_resistance[i] = ei * t.length[i];
        t.cost_ratio[i] = t.length[i];
        continue;
      }
      if (b < 0) {  // a continuation node (of an existing network, or a distal branch's first child)
        t.terminals[i] = t.terminals[a];
        load[i] = load[a];
        t.beta[a] = 1;
        t.reduced_resistance[i] = ei * t.length[i] + t.reduced_resistance[a];
        t.cost_ratio[i] = t.length[i] + t.cost_ratio[a];
        continue;
      }
      const auto s = kernelAt(t, i, kernels).split(load[a], t.reduced_resistance[a], load[b], t.reduced_resistance[b], t.radius[i]);
      t.beta[a] = s.beta_a;
      t.beta[b] = s.beta_b;
      t.terminals[i] = t.terminals[a] + t.terminals[b];
      load[i] = load[a] + load[b];
      t.reduced_resistance[i] = ei * t.length[i] + 1.0 / (pow4(s.beta_a) / t.reduced_resistance[a] + pow4(s.beta_b) / t.reduced_resistance[b]);
      t.cost_ratio[i] = t.length[i] + s.beta_a * s.beta_a * t.cost_ratio[a] + s.beta_b * s.beta_b * t.cost_ratio[b];
    }
    const double q_term = o.flow * (1 - reserved) / double(common);
    double change = 0, gamma_change = 0;
    next.resize(t.nodeCount());
    for (auto i : order) {
      const auto par = t.parent[i];
      if (par < 0) {
        t.pressure[i] = o.root_pressure;
        if (t.child0[i] >= 0) t.beta[t.child0[i]] = 1;
        continue;
      }
      t.depth[i] = t.depth[par] + 1;
      t.flow[i] = q_term * load[i];
      t.radius[i] = t.isRoot(par) ? root_radius[std::size_t(t.tree[i])] : t.radius[par] * t.beta[i];
      t.pressure[i] = t.pressure[par] - t.flow[i] * 8.0 * eta[i] * t.length[i] / (std::numbers::pi * pow4(t.radius[i]));
      next[i] = o.viscosity.at(t.radius[i]);
      change = std::max(change, std::abs(next[i] - eta[i]) / next[i]);
      if (banded && t.child1[i] >= 0) {
        const auto& law = kernelAt(t, i, kernels).law();
        gamma_change = std::max(gamma_change, std::abs(law.exponentAt(t.radius[i]) - law.exponentAt(radius_used[std::size_t(i)])));
      }
    }
    // The tree keeps the viscosities its radii and pressures were computed with (consistent to
    // rounding); they differ from η(r) by less than the tolerance.
    if (change < tolerance && gamma_change <= 1e-13) return it;
    if (it >= 200) throw GrowthError("the radius–viscosity fixed point (Algorithm 1) did not converge in 200 iterations");
    for (auto i : order)
      if (t.parent[i] >= 0) eta[i] = next[i];
  }
}

VascularTree growDcco(const DccoOptions& o, GrowthReport& report, DccoReport& dcco, const ProgressFn& progress) {
  DccoGrower g(o, report, dcco);
  return g.run(progress);
}

}  // namespace angiosynth
