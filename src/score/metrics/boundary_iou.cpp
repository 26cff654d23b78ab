// Boundary IoU (Cheng et al. 2021): the IoU of the masks' inner boundary bands, which weighs a
// thin vessel's wall as much as a thick one's instead of by its volume; and the IoU and Boundary
// IoU of the two masks' bounding boxes as the TopCoW 2024 evaluation reports them for its region
// of interest (Yang et al. 2023).
#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <initializer_list>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/distance_transform.hpp"
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

constexpr double kDiagonalShare = 0.02;    // Cheng et al.'s default band: 2 % of the image diagonal
constexpr double kBoxBoundaryRatio = 0.2;  // TopCoW 2024: the box's shell is 20 % of its size per axis (rounded up)

struct Box {
  std::array<std::int64_t, 3> lo{}, hi{};  // inclusive voxel indices
  bool empty = true;
  std::int64_t size(int a) const { return hi[a] - lo[a] + 1; }
};

Box boundingBox(const Volume<std::uint8_t>& v) {
  Box b;
  const VolumeGrid& g = v.grid;
  for (std::int64_t k = 0; k < g.dims[2]; ++k)
    for (std::int64_t j = 0; j < g.dims[1]; ++j)
      for (std::int64_t i = 0; i < g.dims[0]; ++i) {
        if (!v.at(i, j, k)) continue;
        const std::array<std::int64_t, 3> p{i, j, k};
        for (int a = 0; a < 3; ++a) {
          b.lo[a] = b.empty ? p[a] : std::min(b.lo[a], p[a]);
          b.hi[a] = b.empty ? p[a] : std::max(b.hi[a], p[a]);
        }
        b.empty = false;
      }
  return b;
}

}  // namespace

namespace {

// The band by looking around each foreground voxel: the offsets within d, nearest first, until a
// background voxel or the grid's edge. Vessel masks are sparse and the band a few voxels wide.
Volume<std::uint8_t> bandByNeighbours(const Volume<std::uint8_t>& v, const std::vector<std::array<int, 3>>& offsets) {
  const VolumeGrid& g = v.grid;
  Volume<std::uint8_t> band(g);
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, g.dims[2]), [&](const tbb::blocked_range<std::int64_t>& r) {
    for (std::int64_t k = r.begin(); k < r.end(); ++k)
      for (std::int64_t j = 0; j < g.dims[1]; ++j)
        for (std::int64_t i = 0; i < g.dims[0]; ++i) {
          if (!v.at(i, j, k)) continue;
          bool near = false;
          for (const auto& o : offsets) {
            const std::int64_t x = i + o[0], y = j + o[1], z = k + o[2];
            if (!g.contains(x, y, z) || !v.at(x, y, z)) {
              near = true;
              break;
            }
          }
          band.at(i, j, k) = near;
        }
  });
  return band;
}

// The band from the distance transform over the mask's bounding box and a voxel of background
// around it (for wide bands, where the neighbourhoods would be large).
Volume<std::uint8_t> bandByDistances(const Volume<std::uint8_t>& v, const Box& box, double d) {
  const VolumeGrid& g = v.grid;
  Volume<std::uint8_t> band(g);
  const bool planar = g.dims[2] == 1;
  std::array<std::int64_t, 3> lo, n;
  for (int a = 0; a < 3; ++a) {
    const int pad = a == 2 && planar ? 0 : 1;
    lo[a] = box.lo[a] - pad;
    n[a] = box.size(a) + 2 * pad;
  }
  std::vector<double> d2(std::size_t(n[0] * n[1] * n[2]), 0.0);
  const auto at = [&](std::int64_t i, std::int64_t j, std::int64_t k) { return std::size_t(i - lo[0] + n[0] * (j - lo[1] + n[1] * (k - lo[2]))); };
  for (std::int64_t k = box.lo[2]; k <= box.hi[2]; ++k)
    for (std::int64_t j = box.lo[1]; j <= box.hi[1]; ++j)
      for (std::int64_t i = box.lo[0]; i <= box.hi[0]; ++i)
        if (v.at(i, j, k)) d2[at(i, j, k)] = kFarSquared;
  squaredDistances(d2, {int(n[0]), int(n[1]), int(n[2])}, {g.spacing_mm.x, g.spacing_mm.y, g.spacing_mm.z}, planar ? 2 : 3);
  const double limit = d * d * (1 + 1e-12);
  for (std::int64_t k = box.lo[2]; k <= box.hi[2]; ++k)
    for (std::int64_t j = box.lo[1]; j <= box.hi[1]; ++j)
      for (std::int64_t i = box.lo[0]; i <= box.hi[0]; ++i) band.at(i, j, k) = v.at(i, j, k) && d2[at(i, j, k)] <= limit;
  return band;
}

}  // namespace

// Cheng et al. pad the image so that the grid's edge counts as boundary.
Volume<std::uint8_t> innerBoundaryBand(const Volume<std::uint8_t>& v, double d) {
  const VolumeGrid& g = v.grid;
  const Box box = boundingBox(v);
  if (box.empty) return Volume<std::uint8_t>(g);
  const Vec3 h = g.spacing_mm;
  const double limit = d * d * (1 + 1e-12);
  std::array<int, 3> reach{};
  for (int a = 0; a < 3; ++a) reach[a] = a == 2 && g.dims[2] == 1 ? 0 : int(std::min<double>(std::floor(d / h[a] * (1 + 1e-12)), 1 << 20));
  if (double(2 * reach[0] + 1) * (2 * reach[1] + 1) * (2 * reach[2] + 1) > 729) return bandByDistances(v, box, d);
  std::vector<std::pair<double, std::array<int, 3>>> within;
  for (int z = -reach[2]; z <= reach[2]; ++z)
    for (int y = -reach[1]; y <= reach[1]; ++y)
      for (int x = -reach[0]; x <= reach[0]; ++x) {
        const double r2 = std::pow(x * h[0], 2) + std::pow(y * h[1], 2) + std::pow(z * h[2], 2);
        if ((x || y || z) && r2 <= limit) within.push_back({r2, {x, y, z}});
      }
  std::stable_sort(within.begin(), within.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::array<int, 3>> offsets;
  for (const auto& w : within) offsets.push_back(w.second);
  return bandByNeighbours(v, offsets);
}

namespace {

// The default band width: 2 % of the diagonal of the grid's extent (its plane for one slice),
// at least the smallest voxel edge.
double defaultBandWidth(const VolumeGrid& g) {
  double diag2 = 0;
  for (int a = 0; a < 3; ++a)
    if (g.dims[a] > 1) diag2 += std::pow(g.dims[a] * g.spacing_mm[a], 2);
  return std::max(smallestEdge(g), kDiagonalShare * std::sqrt(diag2));
}

// Voxels common to boxes given as inclusive index ranges (an empty range: none).
std::int64_t commonVoxels(std::initializer_list<const Box*> boxes) {
  std::int64_t n = 1;
  for (int a = 0; a < 3; ++a) {
    std::int64_t lo = INT64_MIN, hi = INT64_MAX;
    for (const Box* b : boxes) lo = std::max(lo, b->lo[a]), hi = std::min(hi, b->hi[a]);
    n *= std::max<std::int64_t>(0, hi - lo + 1);
  }
  return n;
}

// The box's core: its voxels farther than ceil(ratio × size) voxels from every face along that
// face's axis, so that the shell is the box without its core (ratio 0.5: no core).
Box coreOf(const Box& b, double ratio) {
  Box c = b;
  for (int a = 0; a < 3; ++a) {
    const auto t = std::int64_t(std::ceil(double(b.size(a)) * ratio - 1e-9));
    c.lo[a] = b.lo[a] + t;
    c.hi[a] = b.hi[a] - t;
  }
  return c;
}

// IoU of the two boxes' shells by inclusion and exclusion over box intersections: exact, without
// visiting voxels.
double shellIoU(const Box& p, const Box& t, double ratio) {
  const Box cp = coreOf(p, ratio), ct = coreOf(t, ratio);
  const std::int64_t shell_p = commonVoxels({&p}) - commonVoxels({&cp}), shell_t = commonVoxels({&t}) - commonVoxels({&ct});
  const std::int64_t both = commonVoxels({&p, &t}) - commonVoxels({&cp, &t}) - commonVoxels({&p, &ct}) + commonVoxels({&cp, &ct});
  const std::int64_t either = shell_p + shell_t - both;
  return either > 0 ? double(both) / double(either) : 0.0;
}

}  // namespace

std::optional<double> boxBoundaryIoU(const Volume<std::uint8_t>& a, const Volume<std::uint8_t>& b, double ratio) {
  const Box p = boundingBox(a), t = boundingBox(b);
  if (p.empty || t.empty) return std::nullopt;
  return shellIoU(p, t, ratio);
}

namespace {

Json boxJson(const Box& b) {
  if (b.empty) return nullptr;
  return Json{{"location", {b.lo[0], b.lo[1], b.lo[2]}}, {"size", {b.size(0), b.size(1), b.size(2)}}};
}

Json boundaryIoU(const ScoringCase& c) {
  const double d = c.options.boundary_width_mm ? *c.options.boundary_width_mm : defaultBandWidth(c.truth.grid);
  const Volume<std::uint8_t> bp = innerBoundaryBand(c.prediction, d), bt = innerBoundaryBand(c.truth, d);
  std::int64_t np = 0, nt = 0, both = 0;
  for (std::size_t i = 0; i < bp.data.size(); ++i) {
    np += bp.data[i] != 0;
    nt += bt.data[i] != 0;
    both += bp.data[i] && bt.data[i];
  }
  const std::int64_t either = np + nt - both;
  Json j{{"band_width_mm", d},
         {"band_voxels_prediction", np},
         {"band_voxels_truth", nt},
         {"boundary_iou", either > 0 ? Json(double(both) / double(either)) : Json(c.topcow() ? 0.0 : 1.0)}};
  const Box p = boundingBox(c.prediction), t = boundingBox(c.truth);
  Json box{{"prediction", boxJson(p)}, {"truth", boxJson(t)}, {"boundary_distance_ratio", kBoxBoundaryRatio}};
  const Json none = c.topcow() ? Json(0.0) : Json(nullptr);
  const bool boxes = !p.empty && !t.empty;
  box["iou"] = boxes ? Json(shellIoU(p, t, 0.5)) : none;
  box["boundary_iou"] = boxes ? Json(shellIoU(p, t, kBoxBoundaryRatio)) : none;
  j["bounding_box"] = box;
  return j;
}

}  // namespace

extern const ScoreMetric kBoundaryIoUMetric{
    "boundary_iou",
    "Boundary IoU (Cheng et al. 2021): |Bp ∩ Bt| / |Bp ∪ Bt| of the inner boundary bands, each mask's voxels within band_width_mm "
    "(Euclidean, between voxel centres) of a background voxel, the outside of the grid counting as background; the band 2 % of "
    "the grid's diagonal unless given, at least one voxel; both bands empty: 1 (TopCoW: 0). bounding_box: the two masks' boxes "
    "(voxel location and size) with their IoU and Boundary IoU as the TopCoW 2024 evaluation computes them, the shell "
    "ceil(0.2 × size) voxels deep per axis; null when a mask is empty (TopCoW: 0)",
    {{"boundary_iou", "/boundary_iou"}, {"box_iou", "/bounding_box/iou"}, {"box_boundary_iou", "/bounding_box/boundary_iou"}},
    boundaryIoU};

}  // namespace angiosynth
