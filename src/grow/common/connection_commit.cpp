#include "grow/common/connection_commit.hpp"

namespace angiosynth {
namespace {

void save(ConnectionUndo& u, const VascularTree& t, const std::vector<double>& rel, std::int32_t id) {
  u.saved.push_back({id, t.terminals[id], t.reduced_resistance[id], t.cost_ratio[id], t.beta[id], rel[id]});
}

}  // namespace

ConnectionUndo commitConnection(VascularTree& t, const Connection& c, const BifurcationOptimizer& opt, const PowerKernel& k,
                                std::vector<double>& rel) {
  const auto s = c.segment, P = t.parent[s];
  ConnectionUndo u{s, P, t.length[s], {}};
  save(u, t, rel, s);
  for (std::size_t lv = 1; lv < c.path.size(); ++lv) {
    save(u, t, rel, c.path[lv].segment);
    save(u, t, rel, c.path[lv].other);
  }
  const auto b = t.addNode(c.bifurcation, -1);
  t.parent[b] = P;
  t.replaceChild(P, s, b);
  t.parent[s] = b;
  t.child0[b] = s;
  t.length[b] = distance(t.position[P], c.bifurcation);
  t.length[s] = distance(c.bifurcation, t.position[s]);
  const auto term = t.addNode(c.terminal, b);
  // Banded γ reads each parent's radius (the last solved): the new bifurcation's takes s's.
  if (k.law().banded()) t.radius[b] = t.radius[term] = t.radius[s];
  const auto sv = opt.shortened(s, t.length[s]);
  t.reduced_resistance[s] = sv.reduced_resistance;
  t.cost_ratio[s] = sv.cost_ratio;
  t.reduced_resistance[term] = t.length[term];
  t.cost_ratio[term] = k.lengthCost(t.length[term]);
  rel.resize(t.nodeCount());
  // The path bottom-up, then relative radii top-down.
  const auto ids = [&](std::size_t lv, std::int32_t& seg, std::int32_t& child, std::int32_t& other) {
    const auto& L = c.path[lv];
    seg = lv == 0 ? b : L.segment;
    child = lv == 0 ? s : (lv == 1 ? b : L.child);
    other = lv == 0 ? term : L.other;
  };
  for (std::size_t lv = 0; lv < c.path.size(); ++lv) {
    std::int32_t seg, child, other;
    ids(lv, seg, child, other);
    t.terminals[seg] = c.path[lv].terminals;
    t.reduced_resistance[seg] = c.path[lv].reduced_resistance;
    t.cost_ratio[seg] = c.path[lv].cost_ratio;
    t.beta[child] = c.path[lv].beta_child;
    t.beta[other] = c.path[lv].beta_other;
  }
  const auto top = c.path.size() == 1 ? b : c.path.back().segment;
  t.beta[top] = 1;
  rel[top] = 1;
  for (std::size_t lv = c.path.size(); lv-- > 0;) {
    std::int32_t seg, child, other;
    ids(lv, seg, child, other);
    rel[child] = rel[seg] * c.path[lv].beta_child;
    rel[other] = rel[seg] * c.path[lv].beta_other;
  }
  return u;
}

void rollbackConnection(VascularTree& t, const ConnectionUndo& u, std::vector<double>& rel) {
  const auto b = t.nodeCount() - 2;
  t.replaceChild(u.proximal, b, u.s);
  t.parent[u.s] = u.proximal;
  t.length[u.s] = u.length_s;
  t.truncate(b);
  rel.resize(b);
  for (auto it = u.saved.rbegin(); it != u.saved.rend(); ++it) {
    t.terminals[it->id] = it->terminals;
    t.reduced_resistance[it->id] = it->reduced_resistance;
    t.cost_ratio[it->id] = it->cost_ratio;
    t.beta[it->id] = it->beta;
    rel[it->id] = it->rel;
  }
}

void refreshRelative(const VascularTree& t, std::vector<double>& rel) {
  rel.assign(t.nodeCount(), 1.0);
  for (auto i : t.topDownOrder())
    if (i > 0 && t.parent[i] > 0) rel[i] = rel[t.parent[i]] * t.beta[i];
}

}  // namespace angiosynth
