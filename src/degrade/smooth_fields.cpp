// Smooth random fields over the image: a multiplicative bias field (coil sensitivity, beam
// hardening) and an additive background texture (tissue that is not vessel).
#include <cmath>

#include "degrade/blur.hpp"
#include "degrade/bspline_field.hpp"
#include "degrade/effect.hpp"

namespace angiosynth {
namespace {

// A unit-variance random field with correlation length ~ spacing (iid normal coefficients).
BSplineField randomField(const VolumeGrid& g, const Vec3& spacing, Rng& rng) {
  BSplineField f(g, spacing);
  for (auto& c : f.coefficients()) c = static_cast<float>(rng.normal() * BSplineField::kCoefficientGainFor3d);
  f.prepare();
  return f;
}

void applyBias(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const double sigma = std::log1p(p("amplitude"));
  const BSplineField f = randomField(s.grid, p.vec("scale"), ctx.rng);
  // exp of a normal field: the gain is always positive, with median 1.
  forEachVoxelIjk(s.grid, [&](std::int64_t v, std::int64_t i, std::int64_t j, std::int64_t k) {
    s.image.data[v] *= static_cast<float>(std::exp(sigma * f.atVoxel(i, j, k)));
  });
}

void applyTexture(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const int octaves = static_cast<int>(p("octaves"));
  const double persistence = p("persistence");
  Vec3 scale = p.vec("scale");
  std::vector<BSplineField> fields;
  std::vector<float> weight;
  double norm = 0;
  for (int o = 0; o < octaves; ++o) {
    // Octaves finer than two voxels add nothing a voxel can show; none is finer than a voxel on
    // any axis (the memory estimate counts on it).
    const Vec3& h = s.grid.spacing_mm;
    if (scale.x < 2 * h.x && scale.y < 2 * h.y && scale.z < 2 * h.z) break;
    if (scale.x < h.x || scale.y < h.y || scale.z < h.z) break;
    fields.push_back(randomField(s.grid, scale, ctx.rng));
    weight.push_back(static_cast<float>(std::pow(persistence, o)));
    norm += double(weight.back()) * weight.back();
    scale = scale * 0.5;
  }
  ctx.record["octaves_used"] = fields.size();
  if (fields.empty()) return;
  for (auto& w : weight) w = static_cast<float>(w * p("amplitude") / std::sqrt(norm));
  const float mean = static_cast<float>(p("mean")), inside = static_cast<float>(p("vessel_share"));
  // Tissue fills what the vessels leave of each voxel; vessel_share of it textures the vessels too.
  forEachVoxelIjk(s.grid, [&](std::int64_t v, std::int64_t i, std::int64_t j, std::int64_t k) {
    float t = mean;
    for (std::size_t o = 0; o < fields.size(); ++o) t += weight[o] * fields[o].atVoxel(i, j, k);
    const float f = s.fraction->data[v];
    s.image.data[v] += (1.0f - f + inside * f) * t;
  });
}

void applyCompartments(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const int count = static_cast<int>(p("count"));
  // Each compartment owns the voxels where its random field is the largest: smooth, organ-like
  // regions of about `scale` across. Their levels are drawn once, recorded, and blurred across
  // the borders by `edge` (tissue boundaries are not sharper than the PSF).
  std::vector<BSplineField> fields;
  std::vector<double> level;
  nlohmann::ordered_json levels = nlohmann::ordered_json::array();
  for (int c = 0; c < count; ++c) {
    fields.push_back(randomField(s.grid, p.vec("scale"), ctx.rng));
    level.push_back(p("contrast") * ctx.rng.normal());
    levels.push_back(level.back());
  }
  ctx.record["levels"] = levels;
  Volume<float> offset(s.grid);
  forEachVoxelIjk(s.grid, [&](std::int64_t v, std::int64_t i, std::int64_t j, std::int64_t k) {
    int best = 0;
    float top = -INFINITY;
    for (int c = 0; c < count; ++c) {
      const float f = fields[c].atVoxel(i, j, k);
      if (f > top) top = f, best = c;
    }
    offset.data[v] = static_cast<float>(level[best]);
  });
  const double edge = p("edge");
  if (edge > 0) gaussianBlur(offset, Vec3(edge, edge, edge));
  forEachVoxel(s.grid.voxelCount(), [&](std::int64_t v) { s.image.data[v] += (1.0f - s.fraction->data[v]) * offset.data[v]; });
}

void applyContrast(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const double bg = s.background, c = s.vessel - s.background;
  const double gamma = p("gamma"), gain = p("gain"), offset = p("offset");
  if (c == 0) return;
  forEachVoxel(s.grid.voxelCount(), [&](std::int64_t v) {
    const double t = (s.image.data[v] - bg) / c;
    const double g = t >= 0 ? std::pow(t, gamma) : -std::pow(-t, gamma);
    s.image.data[v] = static_cast<float>(bg + offset + gain * c * g);
  });
}

void applyAttenuation(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const int axis = static_cast<int>(p("axis"));
  const double length = p("length");
  forEachVoxelIjk(s.grid, [&](std::int64_t v, std::int64_t i, std::int64_t j, std::int64_t k) {
    const std::int64_t idx[3] = {i, j, k};
    const double depth = (idx[axis] + 0.5) * s.grid.spacing_mm[axis];
    s.image.data[v] *= static_cast<float>(std::exp(-depth / length));
  });
}

}  // namespace

extern const EffectType kBiasField{
    "bias",
    "smooth multiplicative bias field exp(N(0, log(1 + amplitude)²)) with correlation length ~ scale (coil sensitivity, beam hardening)",
    {{"amplitude", ParamKind::Number, 0, 10, nullptr, "typical relative gain deviation (0.2: about ±20 %)"},
     {"scale", ParamKind::Length3, 1e-9, 1e9, "0.5 fov", "control-point spacing of the field (its correlation length); at least 1 voxel", 1}},
    applyBias};

extern const EffectType kTexture{
    "texture",
    "smooth random background texture (tissue), added where the vessels leave room: mean + amplitude × fractal field",
    {{"amplitude", ParamKind::Intensity, 0, 1e9, nullptr, "standard deviation of the texture"},
     {"mean", ParamKind::Intensity, -1e9, 1e9, "0", "added to the background before the texture"},
     {"scale", ParamKind::Length3, 1e-9, 1e9, "0.125 fov", "control-point spacing of the coarsest octave; at least 1 voxel", 1},
     {"octaves", ParamKind::Count, 1, 8, "3", "octaves, each at half the spacing of the previous one"},
     {"persistence", ParamKind::Number, 0, 1, "0.5", "amplitude ratio of successive octaves"},
     {"vessel_share", ParamKind::Probability, 0, 1, "0",
      "share of the texture the vessels take too (vesselFM's foreground texture; 0: tissue only)"}},
    applyTexture};

extern const EffectType kCompartments{
    "compartments",
    "organ and tissue compartments: the field of view split into count smooth regions of about scale across (where each one's "
    "random field is the largest), each adding its own level contrast × N(0, 1) where the vessels leave room",
    {{"count", ParamKind::Count, 1, 16, "3", "number of compartments"},
     {"scale", ParamKind::Length3, 1e-9, 1e9, "0.3 fov", "control-point spacing of the fields (the size of a compartment); at least 2 voxels", 2},
     {"contrast", ParamKind::Intensity, 0, 1e9, nullptr, "standard deviation of the compartments' levels"},
     {"edge", ParamKind::Length, 0, 1e9, "1 voxel", "Gaussian σ of the borders between compartments", 0, 0.25}},
    applyCompartments,
    /*moves_geometry=*/false,
    /*noise=*/false,
    /*working_bytes_per_voxel=*/4 + 8};

extern const EffectType kContrast{
    "contrast",
    "intensity transfer: background + offset + gain·(vessel − background)·t^gamma, t = (I − background)/(vessel − background)",
    {{"gamma", ParamKind::Number, 1e-3, 1e3, "1", "exponent on the normalised intensity"},
     {"gain", ParamKind::Number, -1e3, 1e3, "1", "contrast gain (negative inverts vessels)"},
     {"offset", ParamKind::Intensity, -1e9, 1e9, "0", "intensity offset"}},
    applyContrast};

extern const EffectType kAttenuation{
    "attenuation",
    "depth attenuation along an axis (two-photon, light-sheet): I = I·exp(−depth/length), depth from the first voxel face",
    {{"axis", ParamKind::Count, 0, 2, "2", "axis of depth: 0 = x, 1 = y, 2 = z (depth grows with the index)"},
     {"length", ParamKind::Length, 1e-9, 1e9, nullptr, "attenuation length"}},
    applyAttenuation};

}  // namespace angiosynth
