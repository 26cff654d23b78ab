// A k-space spike: one corrupted k-space sample (an electrical discharge in the scanner room, a
// loose coil connection), which the inverse transform spreads over the whole image as stripes of
// one frequency and orientation (the "herringbone" artefact).
#include <cmath>
#include <string>
#include <utility>

#include "degrade/effect.hpp"
#include "degrade/kspace.hpp"

namespace angiosynth {
namespace {

void applySpike(const Drawn& p, EffectContext& ctx) {
  Volume<float>& image = ctx.state.image;
  const auto& d = image.grid.dims;
  const std::int64_t f[3] = {std::llround(p("kx")), std::llround(p("ky")), std::llround(p("kz"))};
  std::int64_t at[3], mirror[3];
  for (int a = 0; a < 3; ++a) {
    if (std::abs(f[a]) > d[a] / 2) {
      const char* name[] = {"kx", "ky", "kz"};
      throw std::invalid_argument(std::string("k-space spike: ") + name[a] + " = " + std::to_string(f[a]) +
                                  " lies beyond the grid's highest frequency; allowed: " + std::to_string(-(d[a] / 2)) + " to " +
                                  std::to_string(d[a] / 2) + " (cycles per field of view)");
    }
    at[a] = (f[a] % d[a] + d[a]) % d[a];
    mirror[a] = ((-f[a]) % d[a] + d[a]) % d[a];
  }
  KSpace k(image);
  // Its height relative to the image's mean (k-space's centre); added with its mirror so that the
  // image stays real: stripes of 2 × amplitude × mean from crest to trough.
  const std::complex<float> spike = float(p("amplitude")) * std::abs(k.at(0, 0, 0));
  k.at(at[0], at[1], at[2]) += spike;
  k.at(mirror[0], mirror[1], mirror[2]) += std::conj(spike);
  ctx.record["spike_height"] = std::abs(spike);
  std::move(k).toImage(image, /*magnitude=*/false);
}

}  // namespace

extern const EffectType kKSpaceSpike{
    "kspace_spike",
    "a k-space spike: the sample at frequency (kx, ky, kz) (cycles per field of view) and its mirror raised by amplitude × "
    "k-space's centre, stripes of that frequency over the whole image",
    {{"kx", ParamKind::Count, -4096, 4096, nullptr, "frequency along x (cycles per field of view)"},
     {"ky", ParamKind::Count, -4096, 4096, "0", "frequency along y"},
     {"kz", ParamKind::Count, -4096, 4096, "0", "frequency along z"},
     {"amplitude", ParamKind::Number, 0, 10, nullptr, "the spike's height relative to k-space's centre (the image's mean × voxels)"}},
    applySpike,
    /*moves_geometry=*/false,
    /*noise=*/false,
    /*working_bytes_per_voxel=*/kKSpaceBytesPerVoxel};

}  // namespace angiosynth
