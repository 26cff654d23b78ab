// Effects placed on the vessels themselves: dropouts (gaps in the contrast along a vessel) and
// VascuSynth's shadows (dark blobs centred on vessels).
#include <cmath>
#include <unordered_map>
#include <vector>

#include "degrade/effect.hpp"
#include "degrade/tree_region.hpp"

namespace angiosynth {
namespace {

// 1 in the middle half of the gap, a raised cosine to 0 over each outer quarter.
double gapProfile(double offset, double length) {
  const double x = std::fabs(offset) / (length / 2);  // 0 at the centre, 1 at the ends
  if (x >= 1) return 0;
  if (x <= 0.5) return 1;
  return 0.5 * (1 + std::cos(M_PI * (x - 0.5) / 0.5));
}

void applyDropout(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const VascularTree& t = *s.tree;
  if (t.segmentCount() == 0) return;
  const int count = static_cast<int>(p("count"));
  const double gap = p("length"), depth = p("depth");
  const PlaceOnTree place(t);
  const double contrast = s.vessel - s.background;
  const double reach = 0.87 * std::max({s.grid.spacing_mm.x, s.grid.spacing_mm.y, s.grid.spacing_mm.z});
  std::unordered_map<std::int64_t, float> kept;  // fraction of the vessel signal left per voxel
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (int d = 0; d < count; ++d) {
    double along;
    const std::int32_t seg = place.draw(ctx.rng.uniform(), along);
    const Vec3 a = t.position[t.parent[seg]], b = t.position[seg];
    const Vec3 dir = (b - a) / std::max(t.length[seg], 1e-12);
    const Vec3 centre = a + dir * along;
    const double lo = std::max(0.0, along - gap / 2), hi = std::min(t.length[seg], along + gap / 2);
    const double margin = t.radius[seg] + reach;
    forEachInBox(boxAround(s.grid, a + dir * lo, a + dir * hi, margin), [&](std::int64_t i, std::int64_t j, std::int64_t k) {
      const Vec3 q = s.grid.centre(i, j, k) - a;
      const double x = dot(q, dir);
      if (x < lo - reach || x > hi + reach) return;
      if (norm(q - dir * x) > margin) return;
      const double drop = depth * gapProfile(x - along, gap);
      if (drop <= 0) return;
      auto [it, fresh] = kept.try_emplace(s.grid.flat(i, j, k), 1.0f);
      it->second *= static_cast<float>(1 - drop);
    });
    list.push_back({{"segment", s.originalSegment(seg)}, {"centre_mm", {centre.x, centre.y, centre.z}}, {"length_mm", hi - lo}, {"depth", depth}});
  }
  for (const auto& [v, keep] : kept) s.image.data[v] -= static_cast<float>((1 - keep) * contrast * s.fraction->data[v]);
  ctx.record["gaps"] = list;
}

void applyShadow(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const VascularTree& t = *s.tree;
  if (t.segmentCount() == 0) return;
  const int count = static_cast<int>(p("count"));
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (int n = 0; n < count; ++n) {
    // As VascuSynth: a random segment (uniform over segments), radius = its length.
    const auto seg = static_cast<std::int32_t>(
        1 + std::min<std::uint64_t>(static_cast<std::uint64_t>(ctx.rng.uniform() * t.segmentCount()), t.segmentCount() - 1));
    const Vec3 a = t.position[t.parent[seg]], b = t.position[seg];
    const Vec3 centre = a + (b - a) * ctx.rng.uniform();
    const double radius = std::max(t.length[seg] * p("radius_scale"), 1e-9);
    const double strength = ctx.rng.uniform(p("strength_min"), std::max(p("strength_min"), p("strength_max")));
    const VoxelBox box = boxAround(s.grid, centre, centre, radius);
    forEachInBox(box, [&](std::int64_t i, std::int64_t j, std::int64_t k) {
      const double d = distance(s.grid.centre(i, j, k), centre);
      if (d < radius) s.image.at(i, j, k) *= static_cast<float>(strength + (1 - strength) * d / radius);
    });
    list.push_back(
        {{"segment", s.originalSegment(seg)}, {"centre_mm", {centre.x, centre.y, centre.z}}, {"radius_mm", radius}, {"strength", strength}});
  }
  ctx.record["shadows"] = list;
}

}  // namespace

extern const EffectType kDropout{
    "dropout",
    "vessel dropouts: the contrast of randomly placed stretches of vessel fades to background (gaps a segmenter must bridge); "
    "ground truth keeps the vessel",
    {{"count", ParamKind::Count, 0, 10000, "3", "number of gaps (placed uniformly along the total vessel length)"},
     {"length", ParamKind::Length, 0, 1e9, "4 voxel", "length of each gap along its vessel"},
     {"depth", ParamKind::Probability, 0, 1, "1", "fraction of the vessel contrast removed at the centre of a gap"}},
    applyDropout};

extern const EffectType kShadow{"shadow",
                                "VascuSynth's shadows: dark blobs on random segments, radius = segment length, gain strength at the centre rising "
                                "linearly to 1 at the rim",
                                {{"count", ParamKind::Count, 0, 1000, nullptr, "number of shadows"},
                                 {"strength_min", ParamKind::Number, 0, 1, "0", "least gain at a shadow's centre"},
                                 {"strength_max", ParamKind::Number, 0, 1, "1", "greatest gain at a shadow's centre"},
                                 {"radius_scale", ParamKind::Number, 0, 1e3, "1", "shadow radius in segment lengths"}},
                                applyShadow};

}  // namespace angiosynth
