#include "pipeline/label_outputs.hpp"

#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace angiosynth {

Channel labelChannel(const Label& label, const LabelPolicy& p, const std::string& role) {
  const std::string description = "angiosynth label, policy " + p.name;
  return {role, p.isSoft() ? viewOf(label.soft, false, description) : viewOf(label.values, true, description)};
}

namespace {

// Σ over fixed chunks, added in chunk order: the same sum for any thread count.
template <class F>
double orderedSum(std::int64_t n, F&& term) {
  constexpr std::int64_t kChunk = 1 << 16;
  std::vector<double> part((n + kChunk - 1) / kChunk, 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, part.size()), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t c = r.begin(); c < r.end(); ++c) {
      double s = 0;
      for (std::int64_t v = std::int64_t(c) * kChunk, e = std::min(n, v + kChunk); v < e; ++v) s += term(v);
      part[c] = s;
    }
  });
  double s = 0;
  for (double x : part) s += x;
  return s;
}

}  // namespace

ProfileVisibility profileVisibility(const Profile& profile, const DegradeInput& in, const Volume<float>& degraded, const Volume<float>& fraction) {
  ProfileVisibility out;
  DegradeInput quiet = in;
  quiet.noise_free = true;
  DegradedImage with = degradeImage(profile, quiet);
  const std::int64_t n = degraded.grid.voxelCount();
  const auto& d = degraded.data;
  auto& a = with.image.data;
  const double background_voxels = orderedSum(n, [&](std::int64_t v) { return fraction.data[v] == 0 ? 1.0 : 0.0; });
  const double square_sum = orderedSum(n, [&](std::int64_t v) {
    const double e = double(d[v]) - a[v];
    return fraction.data[v] == 0 || background_voxels == 0 ? e * e : 0.0;
  });
  out.noise_sigma = std::sqrt(square_sum / std::max(1.0, background_voxels > 0 ? background_voxels : double(n)));
  {
    const Volume<float> none(in.truth->fraction.grid);  // the same scene without vessels
    quiet.fraction = &none;
    const DegradedImage without = degradeImage(profile, quiet);
    const auto& b = without.image.data;
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, n, 1 << 14), [&](const tbb::blocked_range<std::int64_t>& r) {
      for (std::int64_t v = r.begin(); v < r.end(); ++v) a[v] -= b[v];
    });
  }
  // Vessels brighter or darker than tissue (a contrast effect may invert them): the sign of the
  // mean difference over the vessels.
  const double mean = orderedSum(n, [&](std::int64_t v) { return double(fraction.data[v]) * a[v]; });
  if (mean < 0)
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, n, 1 << 14), [&](const tbb::blocked_range<std::int64_t>& r) {
      for (std::int64_t v = r.begin(); v < r.end(); ++v) a[v] = -a[v];
    });
  out.contrast = std::move(with.image);
  return out;
}

std::uint64_t labelBytesPerVoxel(const LabelPolicy& p) {
  // The label (1 byte, soft 4); visible keeps the degraded image while the noise-free runs go
  // (their image and working copies: 12 bytes), the empty partial volume (4) and the contrast (4).
  return (p.isSoft() ? 4 : 1) + (p.perProfile() ? 24 : 0);
}

}  // namespace angiosynth
