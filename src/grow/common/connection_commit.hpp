#pragma once
// Applies a recorded connection (BifurcationOptimizer::record) to the tree, and undoes it. The
// new bifurcation node splits segment s, the new terminal hangs from it, and the path to the root
// takes the recorded reduced resistances, radius ratios, cost ratios and terminal counts: the
// incremental update of CCO (Kerautret et al. (OpenCCO) §3.1.3), O(depth). `rel` (radius / root radius, ρ) is
// refreshed along the path and its siblings; deeper descendants keep theirs until refreshRelative.
#include <cstdint>
#include <vector>

#include "core/vascular_tree.hpp"
#include "grow/common/bifurcation_optimizer.hpp"

namespace angiosynth {

struct ConnectionUndo {
  struct Saved {
    std::int32_t id, terminals;
    double reduced_resistance, cost_ratio, beta, rel;
  };
  std::int32_t s, proximal;
  double length_s;
  std::vector<Saved> saved;
};

ConnectionUndo commitConnection(VascularTree& tree, const Connection& c, const BifurcationOptimizer& opt, const PowerKernel& kernel,
                                std::vector<double>& rel);
// Undoes the last commit (its two nodes must be the last two of the tree).
void rollbackConnection(VascularTree& tree, const ConnectionUndo& undo, std::vector<double>& rel);
// ρ of every segment from the stored β, top-down: O(N).
void refreshRelative(const VascularTree& tree, std::vector<double>& rel);

}  // namespace angiosynth
