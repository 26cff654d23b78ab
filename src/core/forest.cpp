#include "core/forest.hpp"

#include <algorithm>

namespace angiosynth {

void assignClassLabels(std::vector<TreeInfo>& trees, std::vector<std::string> kinds) {
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

std::vector<std::uint8_t> segmentClasses(const VascularTree& v, const std::vector<TreeInfo>& trees) {
  std::vector<std::uint8_t> c(v.nodeCount(), 0);
  for (std::int32_t i = 0; i < v.nodeCount(); ++i)
    if (!v.isRoot(i)) c[i] = static_cast<std::uint8_t>(trees.at(v.tree.empty() ? 0 : v.tree[i]).class_label);
  return c;
}

std::uint32_t classColour(int class_label) {
  static const std::uint32_t palette[] = {0xb3262e, 0x2b4c9a, 0x2e8b57, 0xe08a1e, 0x7b3f9e, 0x1e9aa8};
  return palette[(std::max(class_label, 1) - 1) % 6];
}

Forest singleTreeForest(VascularTree tree, const std::string& kind) {
  Forest f;
  f.vessels = std::move(tree);
  f.trees.push_back(TreeInfo{"tree", kind, 1});
  assignClassLabels(f.trees);
  return f;
}

}  // namespace angiosynth
