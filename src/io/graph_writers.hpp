#pragma once
// Tree graph exports: GXL 1.0 (default), VascuSynth's GXL dialect, and Graphviz DOT.
#include <ostream>
#include <string>

#include <vector>

#include "core/forest.hpp"
#include "core/units.hpp"
#include "core/vascular_tree.hpp"

namespace angiosynth {

struct GraphFrame {
  double voxel_mm = 1;     // for position_voxel (map voxels)
  CoherentUnits vs_units;  // VascuSynth dialect: radii in this length unit, flows in its ^3/s
};

// Every writer but VascuSynth's dialect names each node's and segment's tree (its id) and kind
// (artery, vein, ...); `trees` is indexed by VascularTree::tree.
const TreeInfo& treeOf(const std::vector<TreeInfo>& trees, const VascularTree& t, std::int32_t node);

// Valid GXL 1.0: nodes carry type, tree, kind, position (mm), position_voxel; edges tree, kind,
// radius (mm), length (mm), flow (mm^3/s), pressure_proximal and pressure_distal (Pa). Edge e<i>
// ends at node n<i>.
void writeGxl(std::ostream& out, const VascularTree& tree, const std::vector<TreeInfo>& trees, const GraphFrame& frame, const std::string& graph_id);
// VascuSynth 2011's dialect, byte for byte in layout (leading spaces in names and values,
// " bifurication ", 6 significant digits, positions in map voxels) for users' existing scripts.
void writeVascuSynthGxl(std::ostream& out, const VascularTree& tree, const GraphFrame& frame, const std::string& graph_id);
void writeDot(std::ostream& out, const VascularTree& tree, const std::vector<TreeInfo>& trees, const GraphFrame& frame);

// Radius at a node: that of its incoming segment (a root takes its root segment's).
double nodeRadius(const VascularTree& tree, std::int32_t node);
// The lumen volume of segment i (a cylinder, or a truncated cone when it tapers), mm³.
double segmentVolume(const VascularTree& tree, std::int32_t segment);

// VesselGraph-style tables. nodes.csv: id,pos_x,pos_y,pos_z (mm),type,pressure (Pa),tree,kind;
// edges.csv: id,node1id,node2id (proximal, distal),length,radius (mm),flow (mm^3/s),volume (mm^3),tree,kind.
void writeNodesCsv(std::ostream& out, const VascularTree& tree, const std::vector<TreeInfo>& trees);
void writeEdgesCsv(std::ostream& out, const VascularTree& tree, const std::vector<TreeInfo>& trees);
// VTK XML PolyData: one line cell per segment; point data Radius (mm), Tree, Class; cell data
// Radius, Flow, Tree (index in sample.json's trees), Class (1 artery, 2 vein, ...).
void writeVtp(std::ostream& out, const VascularTree& tree, const std::vector<TreeInfo>& trees);
// SWC: one row per node, parents before children; type 1 for a root, 1 + class for vessel nodes
// (2 artery, 3 vein, further kinds on); every root has parent -1.
void writeSwc(std::ostream& out, const VascularTree& tree, const std::vector<TreeInfo>& trees);
// GraphML (directed), readable by NetworkX: node x, y, z, type, radius, tree, kind; edge length,
// radius, flow, tree, kind.
void writeGraphml(std::ostream& out, const VascularTree& tree, const std::vector<TreeInfo>& trees);

}  // namespace angiosynth
