#pragma once
// Shared by the network readers (network_files.cpp, network_graph_files.cpp, network_vtp.cpp):
// a file's vessels as rows, and the tree they assemble into.
#include <string>
#include <vector>

#include "io/network_files.hpp"

namespace angiosynth::network_detail {

// One segment of the file before the tree is assembled.
struct Row {
  std::string id;
  std::string parent;  // empty: a root vessel (.cco) or root sample (SWC)
  Vec3 prox, dist;     // .cco: both ends; SWC: dist only
  double radius = 0, outflow = 0;
  double radius_start = -1;         // a tapered vessel's radius at its proximal end (CSV column radius_start); -1: none
  double wall_start = 0, wall = 0;  // its wall thickness at the proximal and distal end (0: none given)
  std::int16_t stage = -1;
  std::uint8_t role = 0, branching = 0;
  std::string tree_name, kind;  // CSV columns tree and kind (empty: not given)
  int line = 0;
};

// Builds the tree breadth-first from the roots in file order. `swc`: a root row is a root node
// (no segment); else a root row is a root vessel whose proximal point is the root node. Every
// reader's values meet the physical ranges here (core/physical_ranges.hpp), in mm: coordinates,
// radii (0: not given), walls, and at most kMaxJunctionChildren children per node.
ExistingNetwork assemble(const std::string& file, const std::vector<Row>& rows, bool swc, double unit_mm);

// A vessel of a graph file (GXL, CSV, VTP): the indices of its end points, proximal first, and
// its row (id, radius, stage, role, branching, line; prox, dist and parent are filled here).
struct PointSegment {
  std::size_t from = 0, to = 0;
  Row row;
};
// Rows with parents: the vessel ending where a vessel starts is its parent. Throws InputError
// for a point two vessels end at (a cycle or a merge) and for a root point that starts more
// than one vessel (a tree's root has one vessel).
std::vector<Row> rowsFromPoints(const std::string& file, const std::vector<Vec3>& points, std::vector<PointSegment> segments);

// Role and branching named as angiosynth's graphs write them ("" or absent: not set).
std::uint8_t roleNamed(const std::string& file, int line, const std::string& name);
std::uint8_t branchingNamed(const std::string& file, int line, const std::string& name);
// VItA's integer codes (.cco columns, VTP cell arrays vesselFunction and branchingType).
std::uint8_t roleFromVita(const std::string& file, int line, long long code);
std::uint8_t branchingFromVita(const std::string& file, int line, long long code);

ExistingNetwork readGxl(const std::string& file, double unit_mm);
ExistingNetwork readCsv(const std::string& file, double unit_mm);
ExistingNetwork readVtp(const std::string& file, double unit_mm, std::uint64_t memory_limit);

}  // namespace angiosynth::network_detail
