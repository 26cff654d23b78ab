// Previews: maximum-intensity projections (grey or coloured by label) and slices, as 8-bit images.
#include <algorithm>
#include <cmath>

#include "io/volume_writers.hpp"

namespace angiosynth {
namespace {

std::uint8_t to8(float v, double lo, double scale) {
  const double x = (v - lo) * scale;
  return std::isnan(x) ? 0 : static_cast<std::uint8_t>(std::clamp(std::round(x), 0.0, 255.0));
}

// The largest value along `axis` for every pixel (-inf for none) and its voxel (the first on
// ties; -1 for none).
std::vector<std::int64_t> projectionArgmax(const Volume<float>& v, int axis, int& width, int& height, std::vector<float>& best) {
  const auto& d = v.grid.dims;
  const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;  // remaining axes, u < w
  width = d[u];
  height = d[w];
  std::vector<std::int64_t> at(std::size_t(d[u]) * d[w], -1);
  best.assign(at.size(), -INFINITY);
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const std::int64_t c[3] = {i, j, k};
        const auto p = c[u] + std::int64_t(d[u]) * c[w];
        const float x = v.at(i, j, k);
        if (x > best[p]) best[p] = x, at[p] = i + d[0] * (j + std::int64_t(d[1]) * k);
      }
  return at;
}

}  // namespace

Image8 maximumProjection(const Volume<float>& v, int axis, double lo, double hi) {
  Image8 img;
  std::vector<float> best;
  projectionArgmax(v, axis, img.width, img.height, best);
  img.pixels.assign(best.size(), 0);
  const double scale = hi > lo ? 255.0 / (hi - lo) : 1.0;
  for (std::size_t p = 0; p < best.size(); ++p) img.pixels[p] = to8(best[p], lo, scale);
  return img;
}

Image8 maximumProjection(const Volume<float>& v, const Volume<std::uint8_t>& labels, std::uint32_t (*colour_of)(int), int axis, double lo,
                         double hi) {
  Image8 img;
  img.channels = 3;
  std::vector<float> best;
  const auto at = projectionArgmax(v, axis, img.width, img.height, best);
  img.pixels.assign(3 * at.size(), 0);
  const double scale = hi > lo ? 255.0 / (hi - lo) : 1.0;
  for (std::size_t p = 0; p < at.size(); ++p) {
    const int grey = to8(best[p], lo, scale);
    const int label = at[p] < 0 ? 0 : labels.data[at[p]];
    // The class colour brightened to a full channel, so a vessel at full intensity is vivid.
    const std::uint32_t c = label ? colour_of(label) : 0xffffff;
    const int rgb[3] = {int(c >> 16 & 255), int(c >> 8 & 255), int(c & 255)};
    const int top = std::max({rgb[0], rgb[1], rgb[2], 1});
    for (int ch = 0; ch < 3; ++ch) img.pixels[3 * p + ch] = std::uint8_t((grey * rgb[ch] + top / 2) / top);
  }
  return img;
}

Image8 sliceZ(const Volume<float>& v, std::int32_t z, double lo, double hi) {
  const auto& d = v.grid.dims;
  Image8 img{d[0], d[1], std::vector<std::uint8_t>(std::size_t(d[0]) * d[1])};
  const double scale = hi > lo ? 255.0 / (hi - lo) : 1.0;
  const float* s = v.data.data() + std::size_t(z) * img.pixels.size();
  for (std::size_t p = 0; p < img.pixels.size(); ++p) img.pixels[p] = to8(s[p], lo, scale);
  return img;
}

}  // namespace angiosynth
