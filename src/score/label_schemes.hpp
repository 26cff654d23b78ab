#pragma once
// Label schemes of published multi-class vessel challenges: the names of their label values and
// what their evaluations add to the per-class scores. TopCoW 2024 (Yang et al. 2023): the Circle
// of Willis in 13 classes, detection of its "group 2" communicating arteries, classification of
// its anterior and posterior variants, and topology matching. TopBrain 2025: 40 brain-vessel
// classes (CTA track), detection of its "side road" vessels, and each class's neighbours that its
// anatomy does not allow. A scheme may also be read from a JSON file (the same fields).
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace angiosynth {

struct LabelScheme {
  std::string name;
  std::string source;                 // the evaluation it follows
  std::map<int, std::string> labels;  // value → name, background left out
  std::vector<int> detection_labels;  // detected when IoU ≥ detection_iou; TP/FP/FN/TN per case
  std::string detection_name;         // "group 2" (TopCoW), "side road" (TopBrain)
  double detection_iou = 0.25;
  double missing_distance_mm = 90;  // HD95 and HD of a class absent from one side
  bool circle_of_willis = false;    // TopCoW's variant classification and topology matching
  // Each label's neighbours its anatomy allows (26-neighbour touching); empty: no such error.
  std::map<int, std::vector<int>> valid_neighbours;
};

// The schemes built in, by name: topcow2024, topbrain2025-ct.
const std::vector<LabelScheme>& builtInLabelSchemes();
// A built-in scheme by name, else a JSON file of one; an unknown name or a bad file is an
// InputError naming what is allowed.
LabelScheme labelScheme(const std::string& name_or_file);

}  // namespace angiosynth
