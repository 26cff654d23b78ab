#include "degrade/degrade.hpp"

#include <chrono>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "degrade/warp.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

std::uint64_t profileKey(const std::string& name) { return hashName(name.data(), name.size()); }

// The profile's own intensities: plain values or ranges (one draw each, even when fixed).
double drawIntensity(const std::optional<ParamSpec>& spec, double fallback, const char* name, Rng& rng, Json& rec) {
  const double u = rng.uniform();
  const double v = spec ? drawComponent(spec->components[0], u, ParamScale{}, -1) : fallback;
  rec[name] = v;
  return v;
}

}  // namespace

void dtypeRange(const std::string& dtype, double& lo, double& hi) {
  lo = -INFINITY, hi = INFINITY;
  if (dtype == "uint8")
    lo = 0, hi = 255;
  else if (dtype == "uint16")
    lo = 0, hi = 65535;
  else if (dtype == "int16")
    lo = -32768, hi = 32767;
}

DegradedImage degradeImage(const Profile& profile, const DegradeInput& in) {
  DegradedImage out;
  out.profile = profile.name;
  const std::uint64_t pkey = profileKey(profile.name);
  Json& rec = out.record;
  rec["profile"] = profile.name;
  rec["source"] = profile.file;
  if (!profile.description.empty()) rec["description"] = profile.description;
  rec["stream"] = Json{{"seed", in.seed}, {"sample", in.sample}, {"profile_key", pkey}};

  Rng prng(in.seed, in.sample, Stage::Degrade, mix64(pkey));
  DegradeState s;
  s.grid = in.truth->fraction.grid;
  s.background = drawIntensity(profile.background, in.background, "background", prng, rec);
  s.vessel = drawIntensity(profile.vessel, in.vessel, "vessel", prng, rec);
  out.dtype = profile.dtype.empty() ? in.dtype : profile.dtype;
  rec["dtype"] = out.dtype;
  s.fraction = in.fraction ? in.fraction : &in.truth->fraction;
  s.tree = in.tree;
  s.image = Volume<float>(s.grid);
  const float bg = static_cast<float>(s.background), c = static_cast<float>(s.vessel - s.background);
  forEachVoxel(s.grid.voxelCount(), [&](std::int64_t v) { s.image.data[v] = bg + c * s.fraction->data[v]; });

  double lo, hi;
  dtypeRange(out.dtype, lo, hi);
  const ParamScale scale{s.grid, s.background, s.vessel};
  Json effects = Json::array();
  for (std::size_t e = 0; e < profile.effects.size(); ++e) {
    const EffectSpec& spec = profile.effects[e];
    const std::string tname = spec.type->name;
    Rng rng(in.seed, in.sample, Stage::Degrade, mix64(pkey ^ mix64(e + 1) ^ hashName(tname.data(), tname.size())));
    Json er;
    er["type"] = tname;
    // Whether to apply is drawn first, always, so the parameters draw the same either way.
    double probability = 1;
    if (spec.probability) {
      Json ignored;
      probability = drawParams({{"probability", ParamKind::Probability, 0, 1, "1", "probability"}}, {{"probability", *spec.probability}}, scale, rng,
                               ignored, profile.file, spec.line)("probability");
    }
    const bool applied = rng.uniform() < probability;
    er["probability"] = probability;
    er["applied"] = applied;
    Json params;
    const Drawn drawn = drawParams(spec.type->params, spec.params, scale, rng, params, profile.file, spec.line);
    er["parameters"] = params;
    if (applied && !(in.noise_free && spec.type->noise)) {
      const auto t0 = std::chrono::steady_clock::now();
      EffectContext ctx{s, rng, er, profile.file, spec.line};
      try {
        spec.type->apply(drawn, ctx);
      } catch (const std::invalid_argument& ex) { throw InputError(profile.file, spec.line, ex.what()); }
      if (profile.clamp_each_step && std::isfinite(lo))
        forEachVoxel(s.grid.voxelCount(), [&](std::int64_t v) { s.image.data[v] = static_cast<float>(std::clamp(double(s.image.data[v]), lo, hi)); });
      out.seconds[std::to_string(e) + "_" + tname] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    effects.push_back(er);
  }
  rec["effects"] = effects;
  out.background = s.background;
  out.vessel = s.vessel;
  if (s.warp && !in.noise_free) {
    const auto t0 = std::chrono::steady_clock::now();
    out.labels = warpedLabels(*s.warped_fraction, *s.warped_tree, s.segment_origin, in.truth->instances, *s.warp, in.truth->centerline_connectivity);
    out.tree = s.warped_tree;
    out.segment_origin = s.segment_origin;
    out.warp = s.warp;
    out.seconds["warped_labels"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  if (!s.distractors.data.empty()) {
    // A vessel the image shows stays a vessel: a distractor voxel is one the vessel label leaves out.
    const Volume<std::uint8_t>& mask = out.labels ? out.labels->mask : in.truth->mask;
    std::int64_t count[kDistractorKinds + 1] = {};
    for (std::int64_t v = 0; v < s.grid.voxelCount(); ++v) {
      if (mask.data[v]) s.distractors.data[v] = 0;
      ++count[std::min<int>(s.distractors.data[v], kDistractorKinds)];
    }
    Json voxels;
    for (int k = 1; k <= kDistractorKinds; ++k)
      if (count[k]) voxels[distractorName(std::uint8_t(k))] = count[k];
    rec["distractor_voxels"] = voxels;
    out.distractors = std::move(s.distractors);
  }
  out.image = std::move(s.image);
  return out;
}

}  // namespace angiosynth
