#pragma once
// Draws voxels with probability proportional to their current demand in O(log V), and takes
// batched updates that touch only the changed leaves and their ancestors. A sum tree (not a
// Fenwick tree) recomputes each parent from its children, so rounding never drifts.
#include <cstdint>
#include <functional>
#include <span>
#include <utility>
#include <vector>

namespace angiosynth {

class DemandSampler {
 public:
  explicit DemandSampler(const std::vector<float>& demand);
  // The demand changed by `adjust` (given every voxel's value, ≥ 0) before the sums are built:
  // one O(V) pass instead of an update per changed voxel.
  DemandSampler(const std::vector<float>& demand, const std::function<void(std::span<double>)>& adjust);
  static std::uint64_t bytesFor(std::int64_t voxels);
  // A voxel's weight for a map demand: a negative demand draws nothing.
  static double weightOf(float demand) { return demand > 0 ? demand : 0.0; }

  double total() const { return tree_[1]; }
  double value(std::int64_t voxel) const { return tree_[leaves_ + voxel]; }
  // Voxel for u in [0,1); -1 when rounding lands on an empty leaf (draw again).
  std::int64_t sample(double u) const;
  // Sets voxels to new values; `updates` must be sorted by voxel index.
  void update(const std::vector<std::pair<std::int64_t, double>>& updates);

 private:
  std::int64_t leaves_ = 1;
  std::vector<double> tree_;
  std::vector<std::int64_t> scratch_;
};

}  // namespace angiosynth
