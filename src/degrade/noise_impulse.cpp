// Impulse (salt-and-pepper) noise: voxels replaced by fixed values, as detector defects and
// transmission errors do.
#include "degrade/effect.hpp"

namespace angiosynth {
namespace {

void applyImpulse(const Drawn& p, EffectContext& ctx) {
  const CounterStream s{ctx.rng.nextU64()};
  const double ps = p("salt_probability"), pp = p("pepper_probability");
  if (ps + pp > 1) throw std::invalid_argument("impulse noise: salt_probability + pepper_probability exceeds 1");
  const float salt = static_cast<float>(p("salt_value")), pepper = static_cast<float>(p("pepper_value"));
  auto& img = ctx.state.image.data;
  // One uniform per voxel decides, as VascuSynth's SALTPEPPER: u < ps → salt, u < ps + pp → pepper.
  forEachVoxel(static_cast<std::int64_t>(img.size()), [&](std::int64_t v) {
    const double u = s.uniform(static_cast<std::uint64_t>(v));
    if (u < ps)
      img[v] = salt;
    else if (u < ps + pp)
      img[v] = pepper;
  });
}

}  // namespace

extern const EffectType kImpulseNoise{
    "impulse",
    "salt-and-pepper noise: each voxel becomes salt_value or pepper_value with the given probabilities (VascuSynth's SALTPEPPER)",
    {{"salt_value", ParamKind::Intensity, -1e9, 1e9, "vessel", "intensity of salt voxels"},
     {"salt_probability", ParamKind::Probability, 0, 1, nullptr, "probability that a voxel becomes salt"},
     {"pepper_value", ParamKind::Intensity, -1e9, 1e9, "background", "intensity of pepper voxels"},
     {"pepper_probability", ParamKind::Probability, 0, 1, nullptr, "probability that a voxel becomes pepper"}},
    applyImpulse,
    /*moves_geometry=*/false,
    /*noise=*/true};

}  // namespace angiosynth
