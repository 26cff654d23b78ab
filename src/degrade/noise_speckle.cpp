// Speckle: the granular, multiplicative noise of coherent imaging (OCT, OCTA, ultrasound). The
// intensity of an average of `looks` independent speckle patterns is Gamma distributed with
// mean 1 and variance 1/looks (Goodman 1976).
#include <algorithm>
#include <cmath>

#include "degrade/effect.hpp"

namespace angiosynth {
namespace {

void applySpeckle(const Drawn& p, EffectContext& ctx) {
  const CounterStream s{ctx.rng.nextU64()};
  const double looks = p("looks");
  // Gamma(looks, 1/looks) by the Wilson–Hilferty cube of a normal: its mean and variance are
  // those of the Gamma to within 1/(81 looks²).
  const double c = 1.0 / (9.0 * looks);
  auto& img = ctx.state.image.data;
  forEachVoxel(static_cast<std::int64_t>(img.size()), [&](std::int64_t v) {
    double z, unused;
    s.normalPair(static_cast<std::uint64_t>(v), z, unused);
    const double g = std::max(0.0, 1 - c + z * std::sqrt(c));
    img[v] = static_cast<float>(img[v] * g * g * g);
  });
}

}  // namespace

extern const EffectType kSpeckle{
    "speckle",
    "speckle: multiplicative Gamma noise of mean 1 and variance 1/looks (coherent imaging: OCT, OCTA, ultrasound)",
    {{"looks", ParamKind::Number, 1, 1e6, nullptr, "independent speckle patterns averaged per voxel (1: fully developed speckle)"}},
    applySpeckle,
    /*moves_geometry=*/false,
    /*noise=*/true};

}  // namespace angiosynth
