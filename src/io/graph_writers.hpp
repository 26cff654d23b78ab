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

}  // namespace angiosynth
