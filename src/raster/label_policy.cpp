#include "raster/label_policy.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "raster/ground_truth.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

// Calibre bins, radius in voxels (the smallest edge): [0, ¼), [¼, ½), [½, 1), [1, 2), [2, 4), [4, ∞).
constexpr std::array<double, 6> kBinLower{0, 0.25, 0.5, 1, 2, 4};

int calibreBin(double radius_voxels) {
  int b = 0;
  while (b + 1 < int(kBinLower.size()) && radius_voxels >= kBinLower[b + 1]) ++b;
  return b;
}

template <class F>
void forEachVoxelIndex(std::int64_t n, F&& f) {
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, n, 1 << 14), [&](const tbb::blocked_range<std::int64_t>& r) {
    for (std::int64_t v = r.begin(); v < r.end(); ++v) f(v);
  });
}

}  // namespace

const std::vector<std::string>& labelPolicyNames() {
  static const std::vector<std::string> names{"binary", "threshold", "visible", "soft", "ignore"};
  return names;
}

Label makeLabel(const LabelPolicy& p, const GroundTruthVolumes& gt, const LabelNumbering& n, const VisibilityEvidence* evidence) {
  Label out;
  const VolumeGrid& g = gt.fraction.grid;
  const auto& pv = gt.fraction.data;
  if (p.isSoft()) {
    out.soft = Volume<float>(g);
    forEachVoxelIndex(g.voxelCount(), [&](std::int64_t v) { out.soft.data[v] = std::clamp(pv[v], 0.0f, 1.0f); });
    return out;
  }
  out.values = Volume<std::uint8_t>(g);
  const bool kinds = n.by_kind && !gt.classes.data.empty();
  // A vessel voxel's value: 1, or its kind (a voxel below the mask rule has its instance's kind,
  // which the classes volume holds only on mask voxels: such voxels fall back to 1).
  const auto vessel = [&](std::int64_t v) -> std::uint8_t {
    if (!kinds) return 1;
    return gt.classes.data[v] ? gt.classes.data[v] : std::uint8_t(1);
  };
  const double sigma = evidence ? evidence->noise_sigma : 0;
  forEachVoxelIndex(g.voxelCount(), [&](std::int64_t v) {
    std::uint8_t l = 0;
    if (p.name == "binary") {
      l = gt.mask.data[v] ? vessel(v) : 0;
    } else if (p.name == "threshold") {
      l = pv[v] >= p.threshold ? vessel(v) : 0;
    } else if (p.name == "visible") {
      const double c = evidence && evidence->contrast ? evidence->contrast->data[v] : pv[v];
      l = gt.mask.data[v] && pv[v] > 0 && c > 0 && c >= p.visible_snr * sigma ? vessel(v) : 0;
    } else {  // ignore
      if (pv[v] >= p.ignoreHigh())
        l = vessel(v);
      else if (pv[v] > p.ignoreLow() || gt.centerline.data[v])
        l = n.ignore_value;
    }
    out.values.data[v] = l;
  });
  return out;
}

Json labelLengthKept(const Label& label, const LabelPolicy& p, const LabelNumbering& n, const VascularTree& t) {
  return p.isSoft() ? labelLengthKept(nullptr, &label.soft, p, n, t) : labelLengthKept(&label.values, nullptr, p, n, t);
}

Json labelLengthKept(const Volume<std::uint8_t>* values, const Volume<float>* soft, const LabelPolicy& p, const LabelNumbering& n,
                     const VascularTree& t) {
  const VolumeGrid& g = soft ? soft->grid : values->grid;
  const double h = std::min({g.spacing_mm.x, g.spacing_mm.y, g.spacing_mm.z});
  constexpr int kBins = int(kBinLower.size());
  // Per segment and bin: length inside the grid, length on vessel labels (or Σ soft value ×
  // length), length on the ignore label. Summed in segment order: the same for any threads.
  std::vector<std::array<double, 3 * kBins>> per(std::max<std::int32_t>(t.nodeCount(), 1));
  tbb::parallel_for(tbb::blocked_range<std::int32_t>(0, t.nodeCount()), [&](const tbb::blocked_range<std::int32_t>& r) {
    for (std::int32_t s = r.begin(); s < r.end(); ++s) {
      auto& acc = per[s];
      acc.fill(0);
      if (t.parent[s] < 0) continue;
      const Vec3 a = t.position[t.parent[s]], b = t.position[s];
      const double len = distance(a, b);
      if (!(len > 0)) continue;
      const int steps = std::max(1, int(std::ceil(len / (h / 4))));
      const double piece = len / steps;
      for (int k = 0; k < steps; ++k) {
        const double u = (k + 0.5) / steps;
        const Vec3 x = g.index(a + (b - a) * u);
        const std::int64_t i = std::llround(x.x), j = std::llround(x.y), kk = std::llround(x.z);
        if (!g.contains(i, j, kk)) continue;
        const double radius = t.startRadius(s) + (t.radius[s] - t.startRadius(s)) * u;
        const int bin = calibreBin(radius / h);
        acc[3 * bin] += piece;
        const std::int64_t v = g.flat(i, j, kk);
        if (soft) {
          acc[3 * bin + 1] += piece * soft->data[v];
        } else {
          const std::uint8_t l = values->data[v];
          if (l == n.ignore_value && p.name == "ignore")
            acc[3 * bin + 2] += piece;
          else if (l)
            acc[3 * bin + 1] += piece;
        }
      }
    }
  });
  std::array<double, 3 * kBins> sum{};
  for (const auto& acc : per)
    for (int k = 0; k < 3 * kBins; ++k) sum[k] += acc[k];
  Json bins = Json::array();
  double total = 0, kept = 0, ignored = 0;
  for (int b = 0; b < kBins; ++b) {
    const double l = sum[3 * b];
    total += l, kept += sum[3 * b + 1], ignored += sum[3 * b + 2];
    Json e{{"radius_voxels", {kBinLower[b], b + 1 < kBins ? Json(kBinLower[b + 1]) : Json("inf")}},
           {"length_mm", l},
           {"vessel", l > 0 ? Json(sum[3 * b + 1] / l) : Json(nullptr)}};
    if (p.name == "ignore") e["ignore"] = l > 0 ? Json(sum[3 * b + 2] / l) : Json(nullptr);
    bins.push_back(e);
  }
  Json j{{"definition",
          std::string(
              "fraction of the centreline length (sampled every quarter voxel, radius in voxels of the smallest edge) on voxels labelled vessel") +
              (p.isSoft() ? " (soft: the mean label value)" : "") + (p.name == "ignore" ? ", and on the ignore label" : "")},
         {"length_mm", total},
         {"vessel", total > 0 ? Json(kept / total) : Json(nullptr)}};
  if (p.name == "ignore") j["ignore"] = total > 0 ? Json(ignored / total) : Json(nullptr);
  j["by_calibre"] = bins;
  return j;
}

}  // namespace angiosynth
