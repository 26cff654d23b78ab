#pragma once
// Places the bifurcation that connects a new terminal t to segment s so that the cost of the
// whole tree, Σ l^μ r^λ (Hamarneh & Jassi 2010 eq. 8), is minimal. The cost of a trial point is exact and
// costs O(depth): only the new bifurcation and the ancestors of s change their reduced
// resistance, radius ratios and subtree cost; everything else is reused from the tree.
//
// The optimiser: at a stationary point Σ_j w_j (b − x_j)/l_j = 0 with w_j = ∂C/∂l_j > 0 for the
// three segments meeting at b (parent end, old distal end, terminal). The w_j come exactly from
// one walk that carries forward-mode derivatives. BFGS starts from the Weiszfeld metric
// 1/Σ(w_j/l_j), whose plain step is the generalised Weiszfeld point, and backtracks from points
// that cross zero demand; trial points are pushed out to the minimum segment length so the
// search slides along that constraint. A compass search polishes connections that did not
// converge. It reaches lower cost than VascuSynth's 20-step axis hill-climb (tested).
//
// With a length ratio k > 0 each of the three segments must also be at least k times its radius
// (CCO's l > 2r), the radius taken at the connection's start point and scaled by the growth the
// caller predicts: the search slides along these spheres too, so a bifurcation whose optimum
// merges into a node (a disguised multifurcation) is moved out, not left as a stub.
#include <array>
#include <cstdint>
#include <vector>

#include "core/vascular_tree.hpp"
#include "domain/clear_paths.hpp"
#include "physics/hemodynamics.hpp"

namespace angiosynth {

struct DemandMap;

// New values of one segment on the path from the bifurcation to the root after a connection.
struct PathLevel {
  std::int32_t segment;  // the existing ancestor (level 0: -1, the new bifurcation segment)
  std::int32_t child;    // the child on the path (level 0: s)
  std::int32_t other;    // the other child (level 0: -1, the new terminal)
  double beta_child, beta_other;
  double reduced_resistance, cost_ratio;
  std::int32_t terminals;
};

struct Connection {
  std::int32_t segment = -1;  // s, the segment that is split
  Vec3 bifurcation;
  Vec3 terminal;
  double cost = 0;              // whole-tree cost after the connection, mm^(μ+λ)
  double root_radius = 0;       // mm
  std::vector<PathLevel> path;  // filled by `record`
  bool valid = false;
  bool converged = false;               // the quasi-Newton iteration reached a stationary point
  std::array<double, 3> min_lengths{};  // parent part, distal part, terminal (mm), set by optimise
  // Radii of the three segments at `bifurcation` after the connection, set by optimise and polish
  // when a length ratio is on: the walk that costed the point gave them.
  std::array<double, 3> radii{};
};

class BifurcationOptimizer {
 public:
  // length_ratio k: segments at least k × radius × radius_scale long (0: only the absolute
  // minimum); a new root segment k × radius × root_radius_scale. The scales stand for the growth
  // a vessel's radius has still to come; with `radius_share` (each segment's radius over the
  // root's) the two parts of a split segment of share x take radius_scale ×
  // (root_radius_scale / radius_scale)^(x²). `paths`: the obstacles trial points must not cross;
  // null for a caller that checks the domain exactly on the result, as CCO's capsule test does.
  BifurcationOptimizer(const VascularTree& tree, const PhysicsParameters& p, const ClearPaths* paths, double min_segment_length_mm,
                       double length_ratio = 0, double radius_scale = 1, double root_radius_scale = 1,
                       const std::vector<double>* radius_share = nullptr)
      : tree_(tree),
        params_(p),
        kernel_(p),
        paths_(paths),
        min_length_(min_segment_length_mm),
        length_ratio_(length_ratio),
        radius_scale_(radius_scale),
        root_radius_scale_(root_radius_scale),
        radius_share_(radius_share) {}

  // Best valid bifurcation on segment s for terminal t; valid = false when every trial point
  // makes a segment cross a zero-demand voxel or shorter than the minimum length.
  // `start`: a known good point (Kamiya's) to start from instead of the midpoint rule.
  Connection optimise(std::int32_t s, const Vec3& t, int max_iterations = 20, const Vec3* start = nullptr) const;
  // Exact whole-tree cost with the three new lengths (parent part, distal part, terminal).
  double cost(std::int32_t s, double l_up, double l_down, double l_term, std::vector<PathLevel>* record = nullptr) const;
  // The same walk without recording the path (which allocates, once per trial in parallel): the
  // cost, what sizes the root, and the β that give the three new segments their radii.
  struct PathSummary {
    double cost;
    std::int32_t terminals;         // at the root
    double reduced_resistance;      // of the root segment
    double beta_down;               // product of β on the path from the root down to the new bifurcation segment
    double beta_child, beta_other;  // of the split part and of the terminal, at the new bifurcation
  };
  PathSummary summarise(std::int32_t s, double l_up, double l_down, double l_term) const;
  // Exact cost and its derivatives with respect to the three new lengths, from one walk to the
  // root that carries forward-mode derivatives of (R̃, V) of the new bifurcation segment.
  struct Evaluation {
    double cost;
    double d_length[3];             // ∂C/∂l for parent part, distal part, terminal
    std::array<double, 3> radii{};  // of the three new segments (with_radii only), as radiiAt gives them
  };
  Evaluation evaluate(std::int32_t s, const double (&l)[3], bool with_radii = false) const;
  // True if the exact optimum on s lies at s's proximal node: there the pull of the other two
  // segments, weighted by ∂C/∂l, is weaker than the parent part's by 1 % (the weighted Fermat
  // condition), one walk to the root.
  bool optimumAtProximalNode(std::int32_t s, const Vec3& t) const;
  // Cost of the connection at point b (no constraint checks).
  double costAt(std::int32_t s, const Vec3& b, const Vec3& t) const;
  struct Subtree {
    double reduced_resistance, cost_ratio;
  };
  // Values of segment s if it started at distance l_down from its distal node.
  Subtree shortened(std::int32_t s, double l_down) const;
  // Compass-search polish of an optimised connection: escapes where the quasi-Newton step stalls
  // (an obstacle boundary, a minimum length, a flat valley). Applied to the connection growth
  // accepts.
  void polish(Connection& c) const;
  // Fills c.path and c.root_radius for a chosen connection.
  void record(Connection& c) const;
  // True if the three segments meeting at b are long enough and cross no zero-demand voxel.
  bool admissible(std::int32_t s, const Vec3& b, const Vec3& t) const;
  using MinLengths = std::array<double, 3>;
  bool admissible(std::int32_t s, const Vec3& b, const Vec3& t, const MinLengths& m) const;
  // Radii of the three segments meeting at b (parent part, distal part, terminal) after the
  // connection, in the tree as it is now.
  // True if c's three segments keep the length ratio at the radii optimise or polish recorded.
  bool keepsLengthRatio(const Connection& c) const;
  std::array<double, 3> radiiAt(std::int32_t s, const Vec3& b, const Vec3& t) const;

 private:
  template <class Visit>
  double walkToRoot(std::int32_t s, double l_up, double l_down, double l_term, Visit&& visit) const;
  struct Level0 {
    double R, V;
    double beta_a, beta_b;  // of the split part and of the terminal
  };
  // A point already costed with its radii, which the search reuses when it starts there.
  struct Probe {
    Vec3 point;
    Evaluation evaluation;
  };
  MinLengths minimumsFrom(std::int32_t s, const std::array<double, 3>& radii) const;
  Connection search(std::int32_t s, const Vec3& t, const MinLengths& m, int max_iterations, const Vec3* start, const Probe* probe) const;
  Vec3 keepLengths(Vec3 b, const std::array<Vec3, 3>& ends, const MinLengths& m) const;
  // The three lengths from b to the ends, each at least the absolute minimum (parent part, distal
  // part, terminal).
  void lengthsFrom(const Vec3& b, const std::array<Vec3, 3>& ends, double (&l)[3]) const;
  Level0 level0(std::int32_t s, double l_up, double l_down, double l_term) const;

  const VascularTree& tree_;
  const PhysicsParameters& params_;
  PowerKernel kernel_;
  const ClearPaths* paths_;
  double min_length_;
  double length_ratio_;
  double radius_scale_;
  double root_radius_scale_;
  const std::vector<double>* radius_share_;
};

}  // namespace angiosynth
