// Rician noise: the magnitude of a complex signal with Gaussian noise on both channels, as in
// magnitude MR images (TOF-MRA). On a zero signal it is Rayleigh distributed.
#include "degrade/effect.hpp"

#include <cmath>

namespace angiosynth {
namespace {

void applyRician(const Drawn& p, EffectContext& ctx) {
  const CounterStream s{ctx.rng.nextU64()};
  const double sigma = p("sigma");
  auto& img = ctx.state.image.data;
  forEachVoxel(static_cast<std::int64_t>(img.size()), [&](std::int64_t v) {
    double re, im;
    s.normalPair(static_cast<std::uint64_t>(v), re, im);
    re = img[v] + sigma * re;
    im = sigma * im;
    img[v] = static_cast<float>(std::sqrt(re * re + im * im));
  });
}

}  // namespace

extern const EffectType kRicianNoise{
    "rician",
    "Rician noise: |signal + N(0, sigma²) + i·N(0, sigma²)|, the noise of magnitude MR images",
    {{"sigma", ParamKind::Intensity, 0, 1e9, nullptr, "standard deviation of the noise on each of the real and imaginary channels"}},
    applyRician,
    /*moves_geometry=*/false,
    /*noise=*/true};

}  // namespace angiosynth
