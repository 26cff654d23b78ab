#pragma once
// Existing vascular networks as files: VItA's .cco trees (seed 001's public code) and SWC, read
// as the initial tree a growth continues (vascular completion), and .cco written for VItA users.
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "core/forest.hpp"

namespace angiosynth {

// A network as its file gives it. Every node but a root ends the segment of the same id; a
// segment's stage, role, branching and outflow are the file's (0 / -1 where it has none).
struct ExistingNetwork {
  VascularTree tree;                 // positions in mm; radii as in the file (mm), not solved
  std::vector<std::string> ids;      // per node: its id in the file (a .cco vessel's, an SWC sample's)
  std::vector<int> lines;            // per node: the line of the file that defines it
  // .cco header: the tree's inflow (file units^3/s), reference pressure and root radius.
  double flow = 0, reference_pressure = 0, root_radius = 0;
};

// Reads `file` by its extension (.cco, .swc); lengths are multiplied by `unit_mm`. Throws
// InputError (file:line) for malformed rows, unknown ids, cycles and vessels that do not start
// where their parent ends. A node of m ≥ 3 children becomes a chain of m − 2 links at its point
// (VascularTree::isLink).
ExistingNetwork readNetwork(const std::filesystem::path& file, double unit_mm = 1);

// VItA's .cco layout: *Tree (root point, inflow, 0, pressure drop, terminals, terminal pressure,
// vessels, root radius, viscosity tolerance), *Vessels (one row per segment: id, proximal and
// distal points, 0 0 0, outflow fraction, branching 0 none / 1 fixed / 2 versatile / 3 distal,
// radius, resistance, 0, 0, proximal pressure, function 0 distribution / 1 perforator /
// 2 transport, 0, 0, stage) and *Connectivity (id, parent or -1, children). mm, Pa, mm^3/s.
// A forest writes one root vessel (parent -1) per tree.
void writeCco(std::ostream& out, const VascularTree& tree, const std::vector<TreeInfo>& trees);

}  // namespace angiosynth
