#pragma once
// Existing vascular networks as files: VItA's .cco trees (VItA, the public code of Maso Talou et al. 2021) and SWC, read
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
  VascularTree tree;             // positions in mm; radii as in the file (mm), not solved
  std::vector<std::string> ids;  // per node: its id in the file (a .cco vessel's, an SWC sample's)
  std::vector<int> lines;        // per node: the line of the file that defines it
  // Per tree (root order): its name and kind where the file gives them (angiosynth's CSV), else empty.
  std::vector<std::string> tree_names, tree_kinds;
  // .cco header: the tree's inflow (file units^3/s), reference pressure and root radius.
  double flow = 0, reference_pressure = 0, root_radius = 0;
};

// Reads `file` by its extension (.cco, .swc, .gxl, .csv, .vtp); lengths are multiplied by
// `unit_mm`. Throws InputError (file:line) for malformed rows, unknown ids, cycles, vessels that
// do not start where their parent ends and values beyond the physical ranges. A node of m ≥ 3
// children becomes a chain of m − 2 links at its point (VascularTree::isLink). The network's
// memory is estimated from the file's size (or a VTP's declared counts, before any array is
// decoded) and refused beyond `memory_limit` bytes (0: 75 % of physical memory).
ExistingNetwork readNetwork(const std::filesystem::path& file, double unit_mm = 1, std::uint64_t memory_limit = 0);

// Throws InputError (file:line of the node) for a node of more than kMaxJunctionChildren
// children (core/physical_ranges.hpp). The readers take any; what walks a junction's chain of
// links for each of its vessels (growth from an [initial] network, meshing) refuses them up
// front. `use` begins the allowed part ("growth from an initial network takes").
void refuseLargeJunctions(const ExistingNetwork& net, const std::string& file, const std::string& use);

// What one vessel of a network costs while it is read and assembled (its row, its id, the
// tree's arrays), in bytes: the readers' memory estimates multiply this.
inline constexpr std::uint64_t kNetworkBytesPerVessel = 1024;

// VItA's .cco layout: *Tree (root point, inflow, 0, pressure drop, terminals, terminal pressure,
// vessels, root radius, viscosity tolerance), *Vessels (one row per segment: id, proximal and
// distal points, 0 0 0, outflow fraction, branching 0 none / 1 fixed / 2 versatile / 3 distal,
// radius, resistance, 0, 0, proximal pressure, function 0 distribution / 1 perforator /
// 2 transport, 0, 0, stage) and *Connectivity (id, parent or -1, children). mm, Pa, mm^3/s.
// A forest writes one root vessel (parent -1) per tree.
void writeCco(std::ostream& out, const VascularTree& tree, const std::vector<TreeInfo>& trees);

}  // namespace angiosynth
