#include "domain/demand_sampler.hpp"

namespace angiosynth {

std::uint64_t DemandSampler::bytesFor(std::int64_t voxels) {
  std::uint64_t leaves = 1;
  while (leaves < static_cast<std::uint64_t>(voxels)) leaves <<= 1;
  return 2 * leaves * sizeof(double);
}

DemandSampler::DemandSampler(const std::vector<float>& demand) : DemandSampler(demand, {}) {}

DemandSampler::DemandSampler(const std::vector<float>& demand, const std::function<void(std::span<double>)>& adjust) {
  while (leaves_ < static_cast<std::int64_t>(demand.size())) leaves_ <<= 1;
  tree_.assign(2 * leaves_, 0.0);
  for (std::size_t i = 0; i < demand.size(); ++i) tree_[leaves_ + i] = weightOf(demand[i]);
  if (adjust) adjust(std::span<double>(tree_).subspan(std::size_t(leaves_), demand.size()));
  for (std::int64_t k = leaves_ - 1; k >= 1; --k) tree_[k] = tree_[2 * k] + tree_[2 * k + 1];
}

std::int64_t DemandSampler::sample(double u) const {
  double target = u * tree_[1];
  std::int64_t k = 1;
  while (k < leaves_) {
    const double left = tree_[2 * k];
    if (target < left) {
      k = 2 * k;
    } else {
      target -= left;
      k = 2 * k + 1;
    }
  }
  return tree_[k] > 0 ? k - leaves_ : -1;
}

void DemandSampler::update(const std::vector<std::pair<std::int64_t, double>>& updates) {
  scratch_.clear();
  for (const auto& [voxel, v] : updates) {
    tree_[leaves_ + voxel] = v;
    const auto parent = (leaves_ + voxel) >> 1;
    if (scratch_.empty() || scratch_.back() != parent) scratch_.push_back(parent);
  }
  while (!scratch_.empty()) {
    std::size_t out = 0;
    for (std::size_t i = 0; i < scratch_.size(); ++i) {
      const auto k = scratch_[i];
      tree_[k] = tree_[2 * k] + tree_[2 * k + 1];
      if (k > 1 && (out == 0 || scratch_[out - 1] != (k >> 1))) scratch_[out++] = k >> 1;
    }
    scratch_.resize(out);
  }
}

}  // namespace angiosynth
