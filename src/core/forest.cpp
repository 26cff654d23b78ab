#include "core/forest.hpp"

#include <algorithm>

namespace angiosynth {

void assignClassLabels(std::vector<TreeInfo>& trees) {
  std::vector<std::string> kinds{"artery", "vein"};
  for (auto& t : trees) {
    auto it = std::find(kinds.begin(), kinds.end(), t.kind);
    if (it == kinds.end()) it = kinds.insert(kinds.end(), t.kind);
    t.class_label = static_cast<int>(it - kinds.begin()) + 1;
  }
}

std::vector<std::string> kindsByLabel(const std::vector<TreeInfo>& trees) {
  std::vector<std::string> kinds;
  for (const auto& t : trees) {
    if (static_cast<int>(kinds.size()) < t.class_label) kinds.resize(t.class_label);
    kinds[t.class_label - 1] = t.kind;
  }
  return kinds;
}

Forest singleTreeForest(VascularTree tree, const std::string& kind) {
  Forest f;
  f.vessels = std::move(tree);
  f.trees.push_back(TreeInfo{"tree", kind, 1});
  assignClassLabels(f.trees);
  return f;
}

}  // namespace angiosynth
