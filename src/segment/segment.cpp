#include "segment/segment.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "degrade/blur.hpp"

namespace angiosynth {
namespace {

// Eigenvalues of a symmetric 3×3 matrix (xx, yy, zz, xy, xz, yz), in closed form (Smith 1961),
// returned sorted by absolute value: |e[0]| ≤ |e[1]| ≤ |e[2]|.
std::array<double, 3> eigenvaluesByMagnitude(double a, double b, double c, double d, double e, double f) {
  const double p1 = d * d + e * e + f * f;
  std::array<double, 3> l;
  if (p1 <= 1e-30 * (a * a + b * b + c * c) || p1 == 0) {
    l = {a, b, c};
  } else {
    const double q = (a + b + c) / 3;
    const double p2 = (a - q) * (a - q) + (b - q) * (b - q) + (c - q) * (c - q) + 2 * p1;
    const double p = std::sqrt(p2 / 6);
    // B = (A − qI) / p; r = det(B) / 2
    const double ba = (a - q) / p, bb = (b - q) / p, bc = (c - q) / p, bd = d / p, be = e / p, bf = f / p;
    const double r = (ba * (bb * bc - bf * bf) - bd * (bd * bc - bf * be) + be * (bd * bf - bb * be)) / 2;
    // The angle in single precision (relative error ~1e-7 of p, far below the responses' use);
    // cos(φ + 2π/3) from cos φ and sin φ: one cosine instead of two.
    const float phi = r <= -1 ? float(M_PI / 3) : r >= 1 ? 0.0f : std::acos(float(r)) / 3;
    const double c = std::cos(phi), s = std::sqrt(std::max(0.0, 1 - c * c));
    l[0] = q + 2 * p * c;
    l[2] = q + 2 * p * (-0.5 * c - 0.8660254037844386 * s);
    l[1] = 3 * q - l[0] - l[2];
  }
  // Three compare-exchanges by magnitude.
  const auto order = [&](int x, int y) {
    if (std::fabs(l[y]) < std::fabs(l[x])) std::swap(l[x], l[y]);
  };
  order(0, 1), order(1, 2), order(0, 1);
  return l;
}

double divideNonzero(double x, double y) { return x / (y == 0 ? 1e-10 : y); }

// How many eigenvalues of the symmetric matrix are positive: the sign changes of its
// characteristic polynomial's coefficients (Descartes' rule, exact when every root is real).
int positiveEigenvalues(double a, double b, double c, double d, double e, double f) {
  const double trace = a + b + c;
  const double minors = a * b - d * d + a * c - e * e + b * c - f * f;
  const double det = a * (b * c - f * f) - d * (d * c - f * e) + e * (d * f - b * e);
  const double coef[4] = {1, -trace, minors, -det};
  int changes = 0;
  double last = 1;
  for (double x : coef) {
    if (x == 0) continue;
    changes += (x > 0) != (last > 0);
    last = x;
  }
  return changes;
}

// The response of one scale from the scale-normalised Hessian's eigenvalues of the image in
// which vessels are bright, sorted by magnitude. `largest` is Jerman's max of −λ3 over the volume.
using Measure = double (*)(const std::array<double, 3>& l, const SegmentOptions& o, double gamma, double largest);

double frangi(const std::array<double, 3>& l, const SegmentOptions& o, double gamma, double) {
  // Bright tubes: the two large eigenvalues negative (Frangi et al. 1998, as scikit-image does).
  if (std::max(l[1], l[2]) > 0) return 0;
  const double ra = std::pow(divideNonzero(l[1], l[2]), 2);
  const double rb = std::pow(divideNonzero(l[0], std::sqrt(std::fabs(l[1] * l[2]))), 2);
  const double s2 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
  return (1 - std::exp(-ra / (2 * o.alpha * o.alpha))) * std::exp(-rb / (2 * o.beta * o.beta)) * (1 - std::exp(-s2 / (2 * gamma * gamma)));
}

double sato(const std::array<double, 3>& l, const SegmentOptions&, double, double) {
  // Tubeness sqrt(|μ1 μ2|) of the two smallest eigenvalues by value, the smallest negative.
  std::array<double, 3> v = l;
  std::sort(v.begin(), v.end());
  return v[0] < 0 ? std::sqrt(std::fabs(v[0] * v[1])) : 0;
}

double jerman(const std::array<double, 3>& l, const SegmentOptions& o, double, double largest) {
  // Jerman et al. (2016), eigenvalues negated so that a bright tube has λ2, λ3 > 0.
  const double l2 = -l[1], l3 = -l[2];
  double rho = l3 > o.tau * largest ? l3 : (l3 > 0 ? o.tau * largest : 0);
  if (l2 <= 0 || rho <= 0) return 0;
  if (l2 >= rho / 2) return 1;
  return l2 * l2 * (rho - l2) * 27 / std::pow(l2 + rho, 3);
}

struct MethodEntry {
  SegmentMethod describe;
  Measure measure;  // null: a threshold on the image
  // The measure is 0 wherever the Hessian has at least this many positive eigenvalues (4: never
  // known in advance).
  int zero_with_positives = 4;
};

const std::vector<MethodEntry>& registry() {
  static const std::vector<MethodEntry> all{
      {{"otsu", "the image above Otsu's threshold (256-bin histogram; Otsu 1979)"}, nullptr},
      // Frangi: the two largest eigenvalues negative, impossible with two positive ones.
      {{"frangi", "Frangi et al. (1998) vesselness, scale-normalised Hessian, max over scales, as scikit-image's frangi"}, frangi, 2},
      // Sato: the smallest eigenvalue negative, impossible with three positive ones.
      {{"sato", "Sato et al. (1998) tubeness sqrt(|λ1 λ2|) of the two most negative eigenvalues, max over scales, as scikit-image's sato"}, sato, 3},
      {{"jerman", "Jerman et al. (2016) vesselness with the largest eigenvalue regularised by τ, max over scales"}, jerman}};
  return all;
}

const MethodEntry& find(const std::string& name) {
  for (const auto& m : registry())
    if (name == m.describe.name) return m;
  std::string allowed;
  for (const auto& m : registry()) allowed += (allowed.empty() ? "" : ", ") + std::string(m.describe.name);
  throw std::invalid_argument("unknown segmentation method \"" + name + "\"; allowed: " + allowed);
}

// Central differences along an axis in mm, one-sided at the two ends (NumPy's gradient), a row
// of x at a time.
void gradient(const Volume<float>& in, int axis, Volume<float>& out) {
  const VolumeGrid& g = in.grid;
  const std::int64_t nx = g.dims[0], ny = g.dims[1], n = g.dims[axis];
  const std::int64_t stride = axis == 0 ? 1 : axis == 1 ? nx : nx * ny;
  const float inv = float(1 / g.spacing_mm[axis]), half = 0.5f * inv;
  tbb::parallel_for(std::int64_t(0), ny * g.dims[2], [&](std::int64_t row) {
    const float* a = in.data.data() + row * nx;
    float* o = out.data.data() + row * nx;
    if (n == 1) {
      std::fill(o, o + nx, 0.0f);
      return;
    }
    if (axis == 0) {
      o[0] = (a[1] - a[0]) * inv;
      for (std::int64_t i = 1; i + 1 < nx; ++i) o[i] = (a[i + 1] - a[i - 1]) * half;
      o[nx - 1] = (a[nx - 1] - a[nx - 2]) * inv;
      return;
    }
    const std::int64_t pos = axis == 1 ? row % ny : row / ny;
    const float* lo = pos == 0 ? a : a - stride;
    const float* hi = pos == n - 1 ? a : a + stride;
    const float scale = (pos == 0 || pos == n - 1) ? inv : half;
    for (std::int64_t i = 0; i < nx; ++i) o[i] = (hi[i] - lo[i]) * scale;
  });
}

}  // namespace

const std::vector<SegmentMethod>& segmentMethods() {
  static const std::vector<SegmentMethod> all = [] {
    std::vector<SegmentMethod> v;
    for (const auto& m : registry()) v.push_back(m.describe);
    return v;
  }();
  return all;
}

double otsuThreshold(const float* values, std::size_t size) {
  if (size == 0) return 0;
  const auto [lo_it, hi_it] = std::minmax_element(values, values + size);
  const double lo = *lo_it, hi = *hi_it;
  if (hi <= lo) return lo;
  // 256 bins over [lo, hi], each at its centre, and the threshold that maximises the
  // between-class variance (the centre of the last bin of the lower class).
  std::vector<double> count(256, 0.0);
  const double width = (hi - lo) / 256;
  for (std::size_t q = 0; q < size; ++q) count[std::min<std::size_t>(255, std::size_t((values[q] - lo) / width))] += 1;
  double total = 0, total_sum = 0;
  for (int b = 0; b < 256; ++b) total += count[b], total_sum += count[b] * (lo + (b + 0.5) * width);
  double w0 = 0, sum0 = 0, best = -1;
  int best_bin = 0;
  for (int b = 0; b < 255; ++b) {
    w0 += count[b];
    sum0 += count[b] * (lo + (b + 0.5) * width);
    const double w1 = total - w0;
    if (w0 == 0 || w1 == 0) continue;
    const double m0 = sum0 / w0, m1 = (total_sum - sum0) / w1;
    const double between = w0 * w1 * (m0 - m1) * (m0 - m1);
    if (between > best) best = between, best_bin = b;
  }
  return lo + (best_bin + 0.5) * width;
}

std::uint64_t segmentBytesPerVoxel(const SegmentOptions& o) {
  // The mask; for vesselness the blurred image, three gradients and the response (Jerman: the two
  // large eigenvalues of a scale as well).
  if (o.method == "otsu") return 1 + 4;
  return 1 + 4 * 5 + (o.method == "jerman" ? 8 : 0);
}

Volume<std::uint8_t> segment(const Volume<float>& image, const SegmentOptions& o, SegmentSummary& summary, Volume<float>* response) {
  const auto t0 = std::chrono::steady_clock::now();
  const MethodEntry& method = find(o.method);
  const VolumeGrid& g = image.grid;
  summary = SegmentSummary{};
  summary.method = o.method;
  Volume<std::uint8_t> mask(g);
  if (!method.measure) {
    // Above the threshold, as scikit-image's `image > threshold_otsu(image)`; dark vessels: the
    // image negated.
    Volume<float> signed_image = image;
    if (!o.bright)
      for (float& v : signed_image.data) v = -v;
    summary.threshold = o.has_threshold ? o.threshold : otsuThreshold(signed_image.data.data(), signed_image.data.size());
    forEachVoxel(g.voxelCount(), [&](std::int64_t v) { mask.data[v] = signed_image.data[v] > summary.threshold; });
    if (response) *response = std::move(signed_image);
  } else {
    if (o.alpha <= 0 || o.beta <= 0 || o.gamma < 0 || o.tau <= 0 || o.tau > 1)
      throw std::invalid_argument("vesselness constants: alpha > 0, beta > 0, gamma >= 0, 0 < tau <= 1");
    std::vector<double> sigmas = o.sigmas_mm;
    if (sigmas.empty())
      for (double s : {1.0, 2.0, 3.0}) sigmas.push_back(s * g.spacing_mm.x);
    Volume<float> best(g), blurred(g), gx(g), gy(g), gz(g);
    Volume<float> large2, large3;  // Jerman: −λ2, −λ3 of the scale
    if (o.method == "jerman") large2 = Volume<float>(g), large3 = Volume<float>(g);
    for (double sigma : sigmas) {
      if (!(sigma > 0)) throw std::invalid_argument("vesselness scales must be > 0 mm");
      summary.sigmas_voxels.push_back(sigma / g.spacing_mm.x);
      blurred = image;
      if (!o.bright)
        for (float& v : blurred.data) v = -v;
      gaussianBlur(blurred, Vec3(sigma, sigma, sigma), 4, &gx);  // gx is free until the gradients
      gradient(blurred, 0, gx), gradient(blurred, 1, gy), gradient(blurred, 2, gz);
      // The Hessian of each voxel from the gradients' gradients, normalised by σ² (Lindeberg).
      // The σ²-normalised Hessian of each voxel from the gradients' gradients (xx, yy, zz, xy, xz,
      // yz): central differences inside, one-sided on the faces, as NumPy's gradient.
      const std::int64_t sx = 1, sy = g.dims[0], sz = std::int64_t(g.dims[0]) * g.dims[1];
      const double s2 = sigma * sigma, ih[3] = {1 / g.spacing_mm.x, 1 / g.spacing_mm.y, 1 / g.spacing_mm.z};
      const auto entries = [&](std::int64_t v, std::int64_t i, std::int64_t j, std::int64_t k) {
        const bool inside = i > 0 && j > 0 && k > 0 && i + 1 < g.dims[0] && j + 1 < g.dims[1] && k + 1 < g.dims[2];
        if (inside) {
          const auto c = [&](const Volume<float>& f, std::int64_t stride, int axis) {
            return (double(f.data[v + stride]) - f.data[v - stride]) * 0.5 * ih[axis];
          };
          return std::array<double, 6>{s2 * c(gx, sx, 0), s2 * c(gy, sy, 1), s2 * c(gz, sz, 2),
                                       s2 * c(gx, sy, 1), s2 * c(gx, sz, 2), s2 * c(gy, sz, 2)};
        }
        const auto d = [&](const Volume<float>& f, int axis) {
          const std::int64_t idx[3] = {i, j, k};
          const std::int64_t n = g.dims[axis], x = idx[axis];
          const std::int64_t stride = axis == 0 ? sx : axis == 1 ? sy : sz;
          if (n == 1) return 0.0;
          if (x == 0) return (double(f.data[v + stride]) - f.data[v]) * ih[axis];
          if (x == n - 1) return (double(f.data[v]) - f.data[v - stride]) * ih[axis];
          return (double(f.data[v + stride]) - f.data[v - stride]) * 0.5 * ih[axis];
        };
        return std::array<double, 6>{s2 * d(gx, 0), s2 * d(gy, 1), s2 * d(gz, 2), s2 * d(gx, 1), s2 * d(gx, 2), s2 * d(gy, 2)};
      };
      const auto hessian = [&](std::int64_t v, std::int64_t i, std::int64_t j, std::int64_t k) {
        const auto e = entries(v, i, j, k);
        return eigenvaluesByMagnitude(e[0], e[1], e[2], e[3], e[4], e[5]);
      };
      double gamma = o.gamma, largest = 0;
      const auto volumeMax = [&](auto&& value) {
        return tbb::parallel_reduce(
            tbb::blocked_range<std::int64_t>(0, g.voxelCount()), 0.0,
            [&](const tbb::blocked_range<std::int64_t>& r, double m) {
              for (std::int64_t q = r.begin(); q < r.end(); ++q) m = std::max(m, value(q));
              return m;
            },
            [](double x, double y) { return std::max(x, y); });
      };
      if (o.method == "jerman") {
        // Jerman's τ is a share of the scale's largest −λ3: the eigenvalues first, then the measure.
        forEachVoxelIjk(g, [&](std::int64_t v, std::int64_t i, std::int64_t j, std::int64_t k) {
          const auto l = hessian(v, i, j, k);
          large2.data[v] = float(-l[1]), large3.data[v] = float(-l[2]);
        });
        largest = volumeMax([&](std::int64_t q) { return double(large3.data[q]); });
      }
      if (gamma == 0) {
        // Half the largest Hessian norm (its Frobenius norm: no eigenvalues needed).
        const double max_norm = volumeMax([&](std::int64_t q) {
          const std::int64_t i = q % g.dims[0], j = (q / g.dims[0]) % g.dims[1], k = q / (std::int64_t(g.dims[0]) * g.dims[1]);
          const auto e = entries(q, i, j, k);
          return std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + 2 * (e[3] * e[3] + e[4] * e[4] + e[5] * e[5]));
        });
        gamma = std::max(max_norm / 2, 1e-12);
      }
      forEachVoxelIjk(g, [&](std::int64_t v, std::int64_t i, std::int64_t j, std::int64_t k) {
        std::array<double, 3> l;
        if (o.method == "jerman") {
          l = {0.0, -double(large2.data[v]), -double(large3.data[v])};
        } else {
          const auto e = entries(v, i, j, k);
          // Voxels the measure gives nothing, told by the signs alone (no eigenvalues needed).
          if (method.zero_with_positives <= 3 && positiveEigenvalues(e[0], e[1], e[2], e[3], e[4], e[5]) >= method.zero_with_positives) return;
          l = eigenvaluesByMagnitude(e[0], e[1], e[2], e[3], e[4], e[5]);
        }
        best.data[v] = std::max(best.data[v], static_cast<float>(method.measure(l, o, gamma, largest)));
      });
    }
    summary.max_response = *std::max_element(best.data.begin(), best.data.end());
    summary.threshold = o.has_threshold ? o.threshold : o.threshold_fraction * summary.max_response;
    const float t = static_cast<float>(summary.threshold);
    // A response of 0 is never a vessel, whatever the threshold.
    forEachVoxel(g.voxelCount(), [&](std::int64_t v) { mask.data[v] = best.data[v] > 0 && best.data[v] >= t; });
    if (response) *response = std::move(best);
  }
  for (auto m : mask.data) summary.voxels += m;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return mask;
}

}  // namespace angiosynth
