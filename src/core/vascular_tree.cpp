#include "core/vascular_tree.hpp"

#include <stdexcept>

#include "core/vessel_roles.hpp"

namespace angiosynth {

void VascularTree::junctionChildren(std::int32_t i, std::vector<std::int32_t>& out) const {
  // Grown trees have no links: their children directly, without the walk's allocation (graph
  // writers and morphometry ask this of every node).
  const auto plain = [&](std::int32_t c) { return c < 0 || !isLink(c); };
  if (plain(child0[i]) && plain(child1[i])) {
    for (const auto c : {child0[i], child1[i]})
      if (c >= 0) out.push_back(c);
    return;
  }
  // Depth first, child0 before child1, without recursion: a file's junction may have thousands
  // of children, hence a chain of as many links.
  std::vector<std::int32_t> stack;
  const auto push = [&](std::int32_t u) {
    if (child1[u] >= 0) stack.push_back(child1[u]);
    if (child0[u] >= 0) stack.push_back(child0[u]);
  };
  push(i);
  while (!stack.empty()) {
    const auto c = stack.back();
    stack.pop_back();
    if (isLink(c))
      push(c);
    else
      out.push_back(c);
  }
}

NodeType VascularTree::graphType(std::int32_t i) const {
  if (parent[i] < 0) return NodeType::Root;
  if (child0[i] < 0) return NodeType::Terminal;
  if (child1[i] < 0 && !isLink(child0[i])) return NodeType::Continuation;
  if (!isLink(child0[i]) && !isLink(child1[i])) return NodeType::Bifurcation;
  std::vector<std::int32_t> kids;
  junctionChildren(i, kids);
  return kids.size() == 1 ? NodeType::Continuation : kids.size() == 2 ? NodeType::Bifurcation : NodeType::Junction;
}

const char* nodeTypeName(NodeType t) {
  switch (t) {
    case NodeType::Root: return "root";
    case NodeType::Bifurcation: return "bifurcation";
    case NodeType::Terminal: return "terminal";
    case NodeType::Continuation: return "continuation";
    case NodeType::Junction: return "junction";
  }
  return "";
}

bool VascularTree::hasTapers() const {
  for (std::size_t i = 0; i < radius_start.size(); ++i)
    if (radius_start[i] >= 0 && radius_start[i] != radius[i]) return true;
  return false;
}

bool VascularTree::hasWalls() const {
  for (std::size_t i = 0; i < wall.size(); ++i)
    if (wall[i] > 0 || wall_start[i] > 0) return true;
  return false;
}

void VascularTree::reserve(std::size_t n) {
  position.reserve(n);
  parent.reserve(n);
  child0.reserve(n);
  child1.reserve(n);
  terminals.reserve(n);
  length.reserve(n);
  reduced_resistance.reserve(n);
  beta.reserve(n);
  cost_ratio.reserve(n);
  radius.reserve(n);
  flow.reserve(n);
  pressure.reserve(n);
  depth.reserve(n);
  tree.reserve(n);
  stage.reserve(n);
  role.reserve(n);
  branching.reserve(n);
  outflow.reserve(n);
  radius_start.reserve(n);
  wall_start.reserve(n);
  wall.reserve(n);
}

void VascularTree::truncate(std::size_t n) {
  position.resize(n);
  parent.resize(n);
  child0.resize(n);
  child1.resize(n);
  terminals.resize(n);
  length.resize(n);
  reduced_resistance.resize(n);
  beta.resize(n);
  cost_ratio.resize(n);
  radius.resize(n);
  flow.resize(n);
  pressure.resize(n);
  depth.resize(n);
  tree.resize(n);
  stage.resize(n);
  role.resize(n);
  branching.resize(n);
  outflow.resize(n);
  radius_start.resize(n);
  wall_start.resize(n);
  wall.resize(n);
}

void VascularTree::setPieceOf(const VascularTree& t, std::int32_t n, int q, int k, std::int32_t id) {
  const double f = double(q) / k, f0 = double(q - 1) / k;
  const double r0 = t.startRadius(n), r1 = t.radius[n];
  radius[id] = r0 + f * (r1 - r0);
  if (t.radius_start[n] >= 0) radius_start[id] = r0 + f0 * (r1 - r0);
  wall_start[id] = t.wall_start[n] + f0 * (t.wall[n] - t.wall_start[n]);
  wall[id] = t.wall_start[n] + f * (t.wall[n] - t.wall_start[n]);
  flow[id] = t.flow[n];
  terminals[id] = t.terminals[n];
  depth[id] = t.depth[n];
}

std::int32_t VascularTree::addNode(const Vec3& at, std::int32_t parent_node, std::int32_t tree_id) {
  // A copy: `at` may be a node's own position (a link at its junction), which push_back moves.
  const Vec3 p = at;
  const auto id = nodeCount();
  position.push_back(p);
  parent.push_back(parent_node);
  child0.push_back(-1);
  child1.push_back(-1);
  terminals.push_back(1);
  length.push_back(parent_node >= 0 ? distance(position[parent_node], p) : 0.0);
  reduced_resistance.push_back(0);
  beta.push_back(1);
  cost_ratio.push_back(0);
  radius.push_back(0);
  flow.push_back(0);
  pressure.push_back(0);
  depth.push_back(parent_node >= 0 ? depth[parent_node] + 1 : 0);
  tree.push_back(parent_node >= 0 ? tree[parent_node] : tree_id);
  stage.push_back(-1);
  role.push_back(0);
  branching.push_back(0);
  outflow.push_back(0);
  radius_start.push_back(-1);
  wall_start.push_back(0);
  wall.push_back(0);
  if (parent_node >= 0) {
    if (child0[parent_node] < 0)
      child0[parent_node] = id;
    else if (child1[parent_node] < 0)
      child1[parent_node] = id;
    else
      throw std::logic_error("node already has two children");
  }
  return id;
}

void VascularTree::replaceChild(std::int32_t node, std::int32_t old_child, std::int32_t new_child) {
  if (child0[node] == old_child)
    child0[node] = new_child;
  else if (child1[node] == old_child)
    child1[node] = new_child;
  else
    throw std::logic_error("replaceChild: not a child");
}

bool VascularTree::hasStages() const {
  for (auto v : stage)
    if (v >= 0) return true;
  return false;
}

std::vector<std::int32_t> VascularTree::roots() const {
  std::vector<std::int32_t> r;
  for (std::int32_t i = 0; i < nodeCount(); ++i)
    if (parent[i] < 0) r.push_back(i);
  return r;
}

std::int64_t VascularTree::totalTerminals() const {
  std::int64_t n = 0;
  for (auto r : roots())
    if (child0[r] >= 0) n += terminals[child0[r]];
  return n;
}

void VascularTree::appendTree(const VascularTree& t, std::int32_t tree_id) {
  const std::int32_t shift = nodeCount();
  const auto moved = [&](std::int32_t i) { return i >= 0 ? i + shift : -1; };
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    position.push_back(t.position[i]);
    parent.push_back(moved(t.parent[i]));
    child0.push_back(moved(t.child0[i]));
    child1.push_back(moved(t.child1[i]));
    terminals.push_back(t.terminals[i]);
    length.push_back(t.length[i]);
    reduced_resistance.push_back(t.reduced_resistance[i]);
    beta.push_back(t.beta[i]);
    cost_ratio.push_back(t.cost_ratio[i]);
    radius.push_back(t.radius[i]);
    flow.push_back(t.flow[i]);
    pressure.push_back(t.pressure[i]);
    depth.push_back(t.depth[i]);
    tree.push_back(tree_id);
    stage.push_back(t.stage[i]);
    role.push_back(t.role[i]);
    branching.push_back(t.branching[i]);
    outflow.push_back(i < std::int32_t(t.outflow.size()) ? t.outflow[i] : 0.0);
    radius_start.push_back(i < std::int32_t(t.radius_start.size()) ? t.radius_start[i] : -1.0);
    wall_start.push_back(i < std::int32_t(t.wall_start.size()) ? t.wall_start[i] : 0.0);
    wall.push_back(i < std::int32_t(t.wall.size()) ? t.wall[i] : 0.0);
  }
}

std::vector<std::int32_t> VascularTree::topDownOrder() const {
  std::vector<std::int32_t> order;
  order.reserve(position.size());
  for (std::int32_t r = 0; r < nodeCount(); ++r) {
    if (parent[r] >= 0) continue;
    std::size_t k = order.size();
    order.push_back(r);
    for (; k < order.size(); ++k) {
      const auto i = order[k];
      if (child0[i] >= 0) order.push_back(child0[i]);
      if (child1[i] >= 0) order.push_back(child1[i]);
    }
  }
  return order;
}

VascularTree VascularTree::renumbered(const std::vector<std::int32_t>& new_id) const {
  VascularTree t = *this;
  const auto n = std::size_t(nodeCount());
  const auto move = [&](auto& field, const auto& from) {
    if (from.size() != n) return;
    for (std::size_t i = 0; i < n; ++i) field[std::size_t(new_id[i])] = from[i];
  };
  const auto index = [&](std::int32_t i) { return i < 0 ? i : new_id[std::size_t(i)]; };
  move(t.position, position);
  move(t.terminals, terminals);
  move(t.length, length);
  move(t.reduced_resistance, reduced_resistance);
  move(t.beta, beta);
  move(t.cost_ratio, cost_ratio);
  move(t.radius, radius);
  move(t.flow, flow);
  move(t.pressure, pressure);
  move(t.depth, depth);
  move(t.tree, tree);
  move(t.stage, stage);
  move(t.role, role);
  move(t.branching, branching);
  move(t.outflow, outflow);
  move(t.radius_start, radius_start);
  move(t.wall_start, wall_start);
  move(t.wall, wall);
  for (std::size_t i = 0; i < n; ++i) {
    const auto j = std::size_t(new_id[i]);
    t.parent[j] = index(parent[i]);
    t.child0[j] = index(child0[i]);
    t.child1[j] = index(child1[i]);
  }
  return t;
}

void VascularTree::removeSubtrees(const std::vector<std::int32_t>& segments, const std::vector<std::int32_t>& prune) {
  std::vector<char> removed(position.size(), 0);
  const auto drop = [&](std::int32_t root) {
    std::vector<std::int32_t> stack{root};
    while (!stack.empty()) {
      const auto i = stack.back();
      stack.pop_back();
      removed[i] = 1;
      if (child0[i] >= 0) stack.push_back(child0[i]);
      if (child1[i] >= 0) stack.push_back(child1[i]);
    }
  };
  for (auto node : prune) {
    if (removed[node] || child0[node] < 0) continue;
    drop(child0[node]);
    if (child1[node] >= 0) drop(child1[node]);
    child0[node] = child1[node] = -1;
  }
  for (auto s : segments) {
    if (s < 0 || parent[s] < 0 || removed[s]) continue;
    const auto p = parent[s];
    const auto sib = sibling(s);
    drop(s);
    replaceChild(p, s, -1);
    if (child0[p] < 0) std::swap(child0[p], child1[p]);
    if (parent[p] >= 0 && sib >= 0 && !(p < std::int32_t(branching.size()) && Branching(branching[p]) == Branching::Distal)) {
      // Bifurcation p now has one child: splice it out, sib hangs from p's parent.
      const auto pp = parent[p];
      replaceChild(pp, p, sib);
      parent[sib] = pp;
      removed[p] = 1;
    }
  }
  // Compact, keeping relative order; rebuild lengths and depths.
  std::vector<std::int32_t> remap(position.size(), -1);
  std::int32_t n = 0;
  for (std::size_t i = 0; i < position.size(); ++i)
    if (!removed[i]) remap[i] = n++;
  VascularTree out;
  out.reserve(n);
  for (std::size_t i = 0; i < position.size(); ++i) {
    if (removed[i]) continue;
    out.position.push_back(position[i]);
    out.parent.push_back(parent[i] >= 0 ? remap[parent[i]] : -1);
    out.child0.push_back(child0[i] >= 0 ? remap[child0[i]] : -1);
    out.child1.push_back(child1[i] >= 0 ? remap[child1[i]] : -1);
    out.tree.push_back(tree.empty() ? 0 : tree[i]);
    out.stage.push_back(i < stage.size() ? stage[i] : -1);
    out.role.push_back(i < role.size() ? role[i] : 0);
    out.branching.push_back(i < branching.size() ? branching[i] : 0);
    out.outflow.push_back(i < outflow.size() ? outflow[i] : 0.0);
  }
  // Merged segments are re-sized by the method: cylinders again, walls as given.
  out.radius_start.assign(out.position.size(), -1.0);
  out.wall_start.assign(out.position.size(), 0.0);
  out.wall.assign(out.position.size(), 0.0);
  const auto m = out.position.size();
  out.terminals.assign(m, 1);
  out.length.assign(m, 0);
  out.reduced_resistance.assign(m, 0);
  out.beta.assign(m, 1);
  out.cost_ratio.assign(m, 0);
  out.radius.assign(m, 0);
  out.flow.assign(m, 0);
  out.pressure.assign(m, 0);
  out.depth.assign(m, 0);
  const auto order = out.topDownOrder();
  for (auto i : order) {
    if (out.parent[i] < 0) continue;
    out.length[i] = distance(out.position[out.parent[i]], out.position[i]);
    out.depth[i] = out.depth[out.parent[i]] + 1;
  }
  for (auto it = order.rbegin(); it != order.rend(); ++it)
    if (out.parent[*it] >= 0 && out.child0[*it] >= 0)  // a continuation (a polyline's node) has one child
      out.terminals[*it] = out.terminals[out.child0[*it]] + (out.child1[*it] >= 0 ? out.terminals[out.child1[*it]] : 0);
  *this = std::move(out);
}

}  // namespace angiosynth
