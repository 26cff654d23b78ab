// Additive noise that does not depend on the signal: Gaussian and uniform.
#include "degrade/effect.hpp"

namespace angiosynth {
namespace {

void applyGaussian(const Drawn& p, EffectContext& ctx) {
  const CounterStream s{ctx.rng.nextU64()};
  const float mean = static_cast<float>(p("mean")), sigma = static_cast<float>(p("sigma"));
  auto& img = ctx.state.image.data;
  const std::int64_t n = static_cast<std::int64_t>(img.size());
  // One Box–Muller pair per two voxels.
  forEachVoxel((n + 1) / 2, [&](std::int64_t pair) {
    double a, b;
    s.normalPair(static_cast<std::uint64_t>(pair), a, b);
    img[2 * pair] += mean + sigma * static_cast<float>(a);
    if (2 * pair + 1 < n) img[2 * pair + 1] += mean + sigma * static_cast<float>(b);
  });
}

void applyUniform(const Drawn& p, EffectContext& ctx) {
  const CounterStream s{ctx.rng.nextU64()};
  const double lo = p("low"), hi = p("high");
  if (lo > hi) throw std::invalid_argument("uniform noise: low > high");
  auto& img = ctx.state.image.data;
  forEachVoxel(static_cast<std::int64_t>(img.size()),
               [&](std::int64_t v) { img[v] += static_cast<float>(lo + (hi - lo) * s.uniform(static_cast<std::uint64_t>(v))); });
}

}  // namespace

extern const EffectType kGaussianNoise{"gaussian",
                                       "additive white Gaussian noise N(mean, sigma²) (VascuSynth's GAUSSIAN)",
                                       {{"mean", ParamKind::Intensity, -1e9, 1e9, "0", "mean of the added noise"},
                                        {"sigma", ParamKind::Intensity, 0, 1e9, nullptr, "standard deviation of the added noise"}},
                                       applyGaussian,
                                       /*moves_geometry=*/false,
                                       /*noise=*/true};

extern const EffectType kUniformNoise{"uniform",
                                      "additive uniform noise U(low, high) (VascuSynth's UNIFORM)",
                                      {{"low", ParamKind::Intensity, -1e9, 1e9, nullptr, "lower bound of the added noise"},
                                       {"high", ParamKind::Intensity, -1e9, 1e9, nullptr, "upper bound of the added noise"}},
                                      applyUniform,
                                      /*moves_geometry=*/false,
                                      /*noise=*/true};

}  // namespace angiosynth
