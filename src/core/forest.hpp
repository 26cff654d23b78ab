#pragma once
// A forest: one or more vascular trees that share one frame (inlets of one organ, an arterial
// and a venous tree). Its vessels are stored as one VascularTree with one root per tree, so
// node and segment ids are unique across the forest and every stage after growth works on all
// trees at once; `vessels.tree[i]` says which tree node i (and segment i) belongs to.
#include <cstdint>
#include <string>
#include <vector>

#include "core/vascular_tree.hpp"

namespace angiosynth {

struct TreeInfo {
  std::string id;       // unique in the forest ("tree", "artery", "inlet_2", ...)
  std::string kind;     // "artery", "vein", or a free name
  int class_label = 1;  // its kind's label in the classes volume (1 artery, 2 vein, further kinds on)
};

struct Forest {
  VascularTree vessels;
  std::vector<TreeInfo> trees;
};

// Class labels of kinds: those of `order` 1, 2, ... (by default artery 1, vein 2), then other
// kinds in order of first appearance. A dataset passes its list so labels agree across samples.
void assignClassLabels(std::vector<TreeInfo>& trees, std::vector<std::string> order = {"artery", "vein"});
// The kinds in label order (index 0 is label 1).
std::vector<std::string> kindsByLabel(const std::vector<TreeInfo>& trees);
// The class label of every segment (by node id; 0 for roots), for the classes volume.
std::vector<std::uint8_t> segmentClasses(const VascularTree& vessels, const std::vector<TreeInfo>& trees);
// Display colour of a class (SVG figures, MIP previews): artery red, vein blue, further kinds
// green, orange, purple, ... as 0xRRGGBB.
std::uint32_t classColour(int class_label);
// One tree as a forest of one (id "tree").
Forest singleTreeForest(VascularTree tree, const std::string& kind = "artery");

}  // namespace angiosynth
