#pragma once
// The vascular tree as struct-of-arrays. Node 0 is the root (perforation point); every other
// node i is the distal end of exactly one segment, which also has id i and runs from node
// parent[i] to node i. The root node has one child segment; bifurcations have two.
// A forest stores several trees in one such structure: each tree has its own root (parent -1),
// `tree[i]` says which tree node i belongs to, and node and segment ids stay unique.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/vec3.hpp"

namespace angiosynth {

// Continuation: a node inside a vessel with one child, as in polyline trees (warped graphs).
// Junction: a node of three or more children (graphs of N-ary networks, see isLink).
enum class NodeType { Root, Bifurcation, Terminal, Continuation, Junction };

struct VascularTree {
  std::vector<Vec3> position;                // mm
  std::vector<std::int32_t> parent;          // proximal node of segment i (-1 for the root)
  std::vector<std::int32_t> child0, child1;  // segments leaving node i (-1: none)
  std::vector<std::int32_t> terminals;       // terminals downstream of segment i
  std::vector<double> length;                // mm
  std::vector<double> reduced_resistance;    // R*·π/(8η) of the subtree of segment i, in mm^-3·mm^4 = mm
  std::vector<double> beta;                  // r_i / r_parent(i); 1 for the root segment
  std::vector<double> cost_ratio;            // Σ_subtree l^μ (r/r_i)^λ
  std::vector<double> radius;                // mm
  std::vector<double> flow;                  // mm^3/s
  std::vector<double> pressure;              // Pa, at node i (distal end of segment i)
  std::vector<std::int32_t> depth;           // segments from the root to node i
  std::vector<std::int32_t> tree;            // index of the tree node i belongs to (0 in a single tree)
  // Staged growth (DCCO): the stage that made segment i (-1: none, the method has no stages), its
  // role (VesselRole) and how it may take new branches (Branching); graphs write them when set.
  std::vector<std::int16_t> stage;
  std::vector<std::uint8_t> role;
  std::vector<std::uint8_t> branching;
  // Prescribed outflow of terminal segment i as a fraction of its tree's inflow (Maso Talou et al.'s
  // outlets to adjacent territories; 0: an ordinary terminal sharing the rest equally).
  std::vector<double> outflow;
  // Tapered vessels (Lázaro 2011: diameter and wall linear along the path): segment i runs from
  // radius_start[i] at its proximal node to radius[i] at its distal node, a cone with spherical
  // caps; −1 (the default) is a cylinder of radius[i]. wall_start/wall: the wall thickness at its
  // two ends (0: none given).
  std::vector<double> radius_start, wall_start, wall;

  bool hasStages() const;
  // True if some segment tapers (radius_start set) or carries a wall thickness.
  bool hasTapers() const;
  bool hasWalls() const;
  // Radius of segment i at its proximal end.
  double startRadius(std::int32_t i) const { return radius_start[i] >= 0 ? radius_start[i] : radius[i]; }
  // The larger of its two radii.
  double maxRadius(std::int32_t i) const { return std::max(radius[i], radius_start[i]); }
  std::int32_t nodeCount() const { return static_cast<std::int32_t>(position.size()); }
  std::int32_t segmentCount() const { return nodeCount() > 0 ? nodeCount() - 1 : 0; }
  // Terminals of the tree rooted at node 0 (growth works on one tree).
  std::int32_t terminalCount() const { return nodeCount() > 1 ? terminals[rootSegment()] : 0; }
  bool isRoot(std::int32_t i) const { return parent[i] < 0; }
  // Root nodes, ascending: one per tree of a forest.
  std::vector<std::int32_t> roots() const;
  // Terminals of every tree.
  std::int64_t totalTerminals() const;
  // The segment leaving the root node.
  std::int32_t rootSegment() const { return child0.empty() ? -1 : child0[0]; }
  bool isTerminal(std::int32_t i) const { return i > 0 && child0[i] < 0; }
  NodeType type(std::int32_t i) const {
    if (parent[i] < 0) return NodeType::Root;
    if (child0[i] < 0) return NodeType::Terminal;
    return child1[i] < 0 ? NodeType::Continuation : NodeType::Bifurcation;
  }
  // A link: a zero-length segment that joins two nodes of one N-ary junction (a network file's
  // node with three or more children is a chain of bifurcations at one point, so the tree stays
  // binary; graph writers and adjacency tests merge the chain back into one junction).
  bool isLink(std::int32_t i) const { return parent[i] >= 0 && position[i] == position[parent[i]]; }
  // The node a link chain hangs from (i itself for an ordinary node).
  std::int32_t junction(std::int32_t i) const {
    while (isLink(i)) i = parent[i];
    return i;
  }
  // Segments leaving the junction of node i (links followed, not listed), appended to out.
  void junctionChildren(std::int32_t i, std::vector<std::int32_t>& out) const;
  // The node's type in a graph, its links merged: a junction of three or more children.
  NodeType graphType(std::int32_t i) const;
  // The other segment leaving the proximal node of segment i (-1 if none).
  std::int32_t sibling(std::int32_t i) const {
    const std::int32_t p = parent[i];
    return child0[p] == i ? child1[p] : child0[p];
  }

  // Appends a node with its incoming segment from `parent_node` (-1 for a root, which starts
  // tree `tree_id`); returns its id.
  std::int32_t addNode(const Vec3& p, std::int32_t parent_node, std::int32_t tree_id = 0);
  // Node `id` ends piece q (1 … k) of segment `seg` of `from`, cut into k equal pieces (warped or
  // curved trees): radius and wall interpolated along it (a tapered vessel's pieces taper), flow,
  // terminal count and depth as the segment's. Pressure, β and the staged attributes are the caller's.
  void setPieceOf(const VascularTree& from, std::int32_t seg, int q, int k, std::int32_t id);
  // Appends every node of `t` (a single tree) as tree `tree_id`, ids shifted by nodeCount().
  void appendTree(const VascularTree& t, std::int32_t tree_id);
  void replaceChild(std::int32_t node, std::int32_t old_child, std::int32_t new_child);
  void reserve(std::size_t nodes);
  // Drops nodes >= n (their links must already be undone).
  void truncate(std::size_t n);
  // Nodes ordered so that every parent precedes its children (breadth-first from each root in turn).
  std::vector<std::int32_t> topDownOrder() const;
  // Removes the given segments together with their subtrees and merges each orphaned
  // bifurcation into one straight segment (not a distal-branching node: it is a given vessel's
  // end, not a split point); node ids are compacted, order is preserved.
  // Nodes in `prune` lose both child subtrees and become terminals (no splice). Pruning comes
  // first; segments inside pruned subtrees are skipped.
  void removeSubtrees(const std::vector<std::int32_t>& segments, const std::vector<std::int32_t>& prune = {});
  // The same tree with node i renamed new_id[i] (a permutation of 0 … n − 1): a tree read from a
  // file gets the file's ids back, and with them its instance labels.
  VascularTree renumbered(const std::vector<std::int32_t>& new_id) const;
};

const char* nodeTypeName(NodeType t);

}  // namespace angiosynth
