// PNG and TIFF through OpenImageIO; kept in one file so only it includes OIIO's headers.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "io/volume_writers.hpp"

namespace angiosynth {
namespace {

OIIO::TypeDesc oiioType(VoxelType t) {
  switch (t) {
    case VoxelType::UInt8: return OIIO::TypeDesc::UINT8;
    case VoxelType::Int16: return OIIO::TypeDesc::INT16;
    case VoxelType::UInt16: return OIIO::TypeDesc::UINT16;
    case VoxelType::UInt32: return OIIO::TypeDesc::UINT32;
    case VoxelType::Float32: return OIIO::TypeDesc::FLOAT;
  }
  return OIIO::TypeDesc::FLOAT;
}

std::uint8_t to8(float v, double lo, double scale) {
  const double x = (v - lo) * scale;
  return std::isnan(x) ? 0 : static_cast<std::uint8_t>(std::clamp(std::round(x), 0.0, 255.0));
}

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& why) {
  throw InputError(file.string(), 0, "cannot write: " + why);
}

}  // namespace

void writeTiff(const std::filesystem::path& file, const VolumeView& v) {
  const VolumeGrid& g = *v.grid;
  auto out = OIIO::ImageOutput::create(file.string());
  if (!out) fail(file, OIIO::geterror());
  OIIO::ImageSpec spec(g.dims[0], g.dims[1], 1, oiioType(v.type));
  spec.attribute("compression", "zip");
  spec.attribute("ImageDescription", v.description);
  spec.attribute("XResolution", float(10.0 / g.spacing_mm.x));  // pixels per cm
  spec.attribute("YResolution", float(10.0 / g.spacing_mm.y));
  spec.attribute("ResolutionUnit", "cm");
  const std::vector<OIIO::ImageSpec> specs(static_cast<std::size_t>(g.dims[2]), spec);
  if (!out->open(file.string(), g.dims[2], specs.data())) fail(file, out->geterror());
  const std::size_t slice = std::size_t(g.dims[0]) * g.dims[1] * voxelBytes(v.type);
  for (std::int32_t z = 0; z < g.dims[2]; ++z) {
    if (z > 0 && !out->open(file.string(), spec, OIIO::ImageOutput::AppendSubimage)) fail(file, out->geterror());
    if (!out->write_image(oiioType(v.type), static_cast<const char*>(v.data) + z * slice)) fail(file, out->geterror());
  }
  if (!out->close()) fail(file, out->geterror());
}

namespace {

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

Image8 maximumProjection(const Volume<float>& v, const Volume<std::uint8_t>& labels, std::uint32_t (*colour_of)(int),
                         int axis, double lo, double hi) {
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

void writePng(const std::filesystem::path& file, const Image8& image) {
  auto out = OIIO::ImageOutput::create(file.string());
  if (!out) fail(file, OIIO::geterror());
  OIIO::ImageSpec spec(image.width, image.height, image.channels, OIIO::TypeDesc::UINT8);
  if (!out->open(file.string(), spec) || !out->write_image(OIIO::TypeDesc::UINT8, image.pixels.data()) || !out->close())
    fail(file, out->geterror());
}

}  // namespace angiosynth
