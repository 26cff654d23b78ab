#pragma once
// Tree graph exports: GXL 1.0 (default), VascuSynth's GXL dialect, and Graphviz DOT.
#include <ostream>
#include <string>

#include "core/units.hpp"
#include "core/vascular_tree.hpp"

namespace angiosynth {

struct GraphFrame {
  double voxel_mm = 1;       // for position_voxel (map voxels)
  CoherentUnits vs_units;    // VascuSynth dialect: radii in this length unit, flows in its ^3/s
};

// Valid GXL 1.0: nodes carry type, position (mm), position_voxel; edges radius (mm), length (mm),
// flow (mm^3/s), pressure_proximal and pressure_distal (Pa). Edge e<i> ends at node n<i>.
void writeGxl(std::ostream& out, const VascularTree& tree, const GraphFrame& frame, const std::string& graph_id);
// VascuSynth 2011's dialect, byte for byte in layout (leading spaces in names and values,
// " bifurication ", 6 significant digits, positions in map voxels) for users' existing scripts.
void writeVascuSynthGxl(std::ostream& out, const VascularTree& tree, const GraphFrame& frame, const std::string& graph_id);
void writeDot(std::ostream& out, const VascularTree& tree, const GraphFrame& frame);

// Radius at a node: that of its incoming segment (the root takes the root segment's).
double nodeRadius(const VascularTree& tree, std::int32_t node);

// VesselGraph-style tables. nodes.csv: id,pos_x,pos_y,pos_z (mm),type,pressure (Pa);
// edges.csv: id,node1id,node2id (proximal, distal),length,radius (mm),flow (mm^3/s),volume (mm^3).
void writeNodesCsv(std::ostream& out, const VascularTree& tree);
void writeEdgesCsv(std::ostream& out, const VascularTree& tree);
// VTK XML PolyData: one line cell per segment; point data Radius (mm), cell data Radius, Flow.
void writeVtp(std::ostream& out, const VascularTree& tree);
// SWC: one row per node, parents before children, type 1 for the root and 0 otherwise.
void writeSwc(std::ostream& out, const VascularTree& tree);
// GraphML (directed), readable by NetworkX: node x, y, z, type, radius; edge length, radius, flow.
void writeGraphml(std::ostream& out, const VascularTree& tree);

}  // namespace angiosynth
