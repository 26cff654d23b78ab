// Poisson–Gaussian noise: photon shot noise on the signal plus Gaussian read-out noise, as in
// fluorescence microscopy and low-dose imaging.
#include "degrade/effect.hpp"

#include <cmath>

#include "core/distributions.hpp"

namespace angiosynth {
namespace {

void applyPoisson(const Drawn& p, EffectContext& ctx) {
  const std::uint64_t key = ctx.rng.nextU64();
  const double gain = p("photons_per_unit"), read = p("read_sigma");
  auto& img = ctx.state.image.data;
  // Each voxel has its own sub-stream, since rejection sampling takes a varying number of draws.
  forEachVoxel(static_cast<std::int64_t>(img.size()), [&](std::int64_t v) {
    Rng r = Rng::fromKey(mix64(key + 0x9e3779b97f4a7c15ULL * static_cast<std::uint64_t>(v + 1)));
    const double photons = static_cast<double>(poisson(std::max(0.0, double(img[v])) * gain, r));
    img[v] = static_cast<float>(photons / gain + (read > 0 ? read * r.normal() : 0.0));
  });
}

}  // namespace

extern const EffectType kPoissonNoise{
    "poisson",
    "Poisson–Gaussian noise: Poisson(signal × photons_per_unit) / photons_per_unit + N(0, read_sigma²)",
    {{"photons_per_unit", ParamKind::Number, 1e-9, 1e9, "1", "detected photons per unit of intensity (the inverse gain)"},
     {"read_sigma", ParamKind::Intensity, 0, 1e9, "0", "standard deviation of the Gaussian read-out noise"}},
    applyPoisson,
    /*moves_geometry=*/false,
    /*noise=*/true};

}  // namespace angiosynth
