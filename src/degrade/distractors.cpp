// Structures an image shows that are not vessels: decoys a segmenter must learn to leave out
// (blobs, tubes like nerves or lymphatics, plates like membranes and bone edges), bone, and
// calcified plaque with the blooming a CT scanner gives it. Each adds its intensity where the
// vessels leave room, never changes a vessel label, and is written to the distractor label so
// that false positives on it can be counted.
#include <algorithm>
#include <cmath>
#include <vector>

#include <tbb/parallel_for.h>

#include "degrade/blur.hpp"
#include "degrade/effect.hpp"
#include "degrade/tree_region.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

// An orthonormal frame {u, v, n} around the unit vector n.
std::array<Vec3, 3> frameAround(const Vec3& n) {
  const Vec3 helper = std::fabs(n.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  Vec3 u = cross(helper, n);
  u = u / norm(u);
  return {u, cross(n, u), n};
}

// A random orthonormal frame: e[2] uniform on the sphere.
std::array<Vec3, 3> randomFrame(Rng& rng) {
  // One draw per statement: the order of a call's arguments is unspecified.
  const double x = rng.normal();
  const double y = rng.normal();
  const double z = rng.normal();
  const Vec3 n(x, y, z);
  return frameAround(n / std::max(norm(n), 1e-12));
}

Vec3 uniformInGrid(const VolumeGrid& g, Rng& rng) {
  double p[3];
  for (int a = 0; a < 3; ++a) p[a] = g.origin_mm[a] + (rng.uniform() * g.dims[a] - 0.5) * g.spacing_mm[a];  // origin: voxel 0's centre
  return Vec3(p[0], p[1], p[2]);
}

Json point(const Vec3& p) { return Json::array({p.x, p.y, p.z}); }

// Paints a shape given by its signed distance (mm, negative inside) within `box`: its partial
// volume is a linear ramp one voxel wide across the surface, it fills what the vessels leave of
// each voxel, and voxels it covers at least half are marked `kind`. `delta(p, depth)` is the
// intensity it adds over the tissue at p, `depth` how far inside (mm). Into `target` when given
// (a buffer blurred afterwards), else into the image.
template <class Sdf, class Delta>
void paintShape(DegradeState& s, const VoxelBox& box, Sdf&& sdf, Delta&& delta, DistractorKind kind, Volume<float>* target = nullptr) {
  if (box.hi[0] < box.lo[0] || box.hi[1] < box.lo[1] || box.hi[2] < box.lo[2]) return;
  if (s.distractors.data.empty()) s.distractors = Volume<std::uint8_t>(s.grid);
  const Vec3& h3 = s.grid.spacing_mm;
  const double h = (h3.x + h3.y + h3.z) / 3;
  Volume<float>& out = target ? *target : s.image;
  tbb::parallel_for(box.lo[2], box.hi[2] + 1, [&](std::int64_t k) {
    for (std::int64_t j = box.lo[1]; j <= box.hi[1]; ++j)
      for (std::int64_t i = box.lo[0]; i <= box.hi[0]; ++i) {
        const Vec3 p = s.grid.centre(i, j, k);
        const double d = sdf(p);
        const double cover = std::clamp(0.5 - d / h, 0.0, 1.0);
        if (cover <= 0) continue;
        const std::int64_t v = s.grid.flat(i, j, k);
        out.data[v] += static_cast<float>(cover * (1.0 - s.fraction->data[v]) * delta(p, -d));
        if (cover >= 0.5) s.distractors.data[v] = static_cast<std::uint8_t>(kind);
      }
  });
}

double drawBetween(Rng& rng, double lo, double hi) { return rng.uniform(lo, std::max(lo, hi)); }

void applyDecoys(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const VolumeGrid& g = s.grid;
  Json list = Json::array();
  const auto intensity = [&] { return drawBetween(ctx.rng, p("intensity_min"), p("intensity_max")); };
  for (int n = 0; n < int(p("blobs")); ++n) {
    const Vec3 c = uniformInGrid(g, ctx.rng);
    const auto e = randomFrame(ctx.rng);
    double semi[3];
    for (double& r : semi) r = drawBetween(ctx.rng, p("blob_radius_min"), p("blob_radius_max"));
    const Vec3 a(semi[0], semi[1], semi[2]);
    const double value = intensity(), amin = std::min({a.x, a.y, a.z}), amax = std::max({a.x, a.y, a.z});
    // Scaled-sphere distance: exact on the surface, within the axis ratio elsewhere.
    paintShape(
        s, boxAround(g, c, c, amax + 2 * g.spacing_mm.x),
        [&](const Vec3& q) {
          const Vec3 r = q - c;
          return (norm(Vec3(dot(r, e[0]) / a.x, dot(r, e[1]) / a.y, dot(r, e[2]) / a.z)) - 1) * amin;
        },
        [&](const Vec3&, double) { return value; }, DistractorKind::Blob);
    list.push_back({{"kind", "blob"}, {"centre_mm", point(c)}, {"semi_axes_mm", point(a)}, {"intensity", value}});
  }
  for (int n = 0; n < int(p("tubes")); ++n) {
    // A gently bent tube (a quadratic Bézier curve), as a nerve or a lymphatic that runs beside vessels.
    const Vec3 a = uniformInGrid(g, ctx.rng);
    const auto e = randomFrame(ctx.rng);
    const double length = drawBetween(ctx.rng, p("tube_length_min"), p("tube_length_max"));
    const double radius = drawBetween(ctx.rng, p("tube_radius_min"), p("tube_radius_max"));
    const double bend = ctx.rng.uniform(-0.25, 0.25) * length;
    const Vec3 b = a + e[2] * length, mid = (a + b) * 0.5 + e[0] * bend;
    const double value = intensity();
    const double step = std::min({g.spacing_mm.x, g.spacing_mm.y, g.spacing_mm.z});
    const int pieces = std::max(4, int(std::ceil(1.5 * length / step)));
    std::vector<Vec3> curve(pieces + 1);
    for (int q = 0; q <= pieces; ++q) {
      const double t = double(q) / pieces;
      curve[q] = a * ((1 - t) * (1 - t)) + mid * (2 * t * (1 - t)) + b * (t * t);
    }
    Vec3 lo = curve[0], hi = curve[0];
    for (const Vec3& c : curve) lo = componentMin(lo, c), hi = componentMax(hi, c);
    // Distances to the curve, piece by piece over each piece's own box: the work grows with the
    // tube's length, not with its bounding box times its pieces.
    const double reach = radius + 2 * step;
    const VoxelBox box = boxAround(g, lo, hi, reach);
    if (box.hi[0] < box.lo[0] || box.hi[1] < box.lo[1] || box.hi[2] < box.lo[2]) continue;
    const std::int64_t nx = box.hi[0] - box.lo[0] + 1, ny = box.hi[1] - box.lo[1] + 1;
    std::vector<float> nearest(std::size_t(nx * ny * (box.hi[2] - box.lo[2] + 1)), INFINITY);
    const auto slot = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
      return std::size_t((i - box.lo[0]) + nx * ((j - box.lo[1]) + ny * (k - box.lo[2])));
    };
    for (int q = 0; q < pieces; ++q)
      forEachInBox(boxAround(g, curve[q], curve[q + 1], reach), [&](std::int64_t i, std::int64_t j, std::int64_t k) {
        float& d = nearest[slot(i, j, k)];
        d = std::min(d, static_cast<float>(pointSegmentDistance(g.centre(i, j, k), curve[q], curve[q + 1])));
      });
    paintShape(
        s, box,
        [&](const Vec3& q) {
          const std::int64_t i = std::llround((q.x - g.origin_mm.x) / g.spacing_mm.x), j = std::llround((q.y - g.origin_mm.y) / g.spacing_mm.y),
                             k = std::llround((q.z - g.origin_mm.z) / g.spacing_mm.z);
          return double(nearest[slot(i, j, k)]) - radius;
        },
        [&](const Vec3&, double) { return value; }, DistractorKind::Tube);
    list.push_back({{"kind", "tube"}, {"start_mm", point(a)}, {"end_mm", point(b)}, {"radius_mm", radius}, {"intensity", value}});
  }
  for (int n = 0; n < int(p("plates")); ++n) {
    const Vec3 c = uniformInGrid(g, ctx.rng);
    const auto e = randomFrame(ctx.rng);
    const double w = drawBetween(ctx.rng, p("plate_extent_min"), p("plate_extent_max"));
    const double h = drawBetween(ctx.rng, p("plate_extent_min"), p("plate_extent_max"));
    const double t = drawBetween(ctx.rng, p("plate_thickness_min"), p("plate_thickness_max"));
    const double value = intensity();
    paintShape(
        s, boxAround(g, c, c, 0.5 * std::sqrt(w * w + h * h + t * t) + 2 * g.spacing_mm.x),
        [&](const Vec3& q) {
          const Vec3 r = q - c;
          return std::max({std::fabs(dot(r, e[0])) - w / 2, std::fabs(dot(r, e[1])) - h / 2, std::fabs(dot(r, e[2])) - t / 2});
        },
        [&](const Vec3&, double) { return value; }, DistractorKind::Plate);
    list.push_back({{"kind", "plate"}, {"centre_mm", point(c)}, {"normal", point(e[2])}, {"size_mm", {w, h, t}}, {"intensity", value}});
  }
  ctx.record["decoys"] = list;
}

void applyBone(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const VolumeGrid& g = s.grid;
  Json list = Json::array();
  for (int n = 0; n < int(p("count")); ++n) {
    // A cap of a spherical shell (skull, vertebral or rib cortex at this scale): centre p0 on the
    // shell's mid-surface, outward normal e[2], curvature radius R.
    const Vec3 p0 = uniformInGrid(g, ctx.rng);
    const auto e = randomFrame(ctx.rng);
    const double R = drawBetween(ctx.rng, p("curvature_radius_min"), p("curvature_radius_max"));
    const double extent = drawBetween(ctx.rng, p("extent_min"), p("extent_max"));
    const double t = drawBetween(ctx.rng, p("thickness_min"), p("thickness_max"));
    const double cortex = p("cortex_thickness"), hard = p("cortex"), soft = p("marrow");
    const Vec3 centre = p0 - e[2] * R;
    const double half_angle = std::min(M_PI, extent / 2 / R);
    paintShape(
        s, boxAround(g, p0, p0, extent / 2 + t + 2 * g.spacing_mm.x),
        [&](const Vec3& q) {
          const Vec3 r = q - centre;
          const double rho = norm(r);
          const double angle = std::acos(std::clamp(dot(r, e[2]) / std::max(rho, 1e-12), -1.0, 1.0));
          return std::max(std::fabs(rho - R) - t / 2, (angle - half_angle) * R);
        },
        [&](const Vec3& q, double) {
          // Cortex within cortex_thickness of either face, marrow between.
          const double inside = t / 2 - std::fabs(norm(q - centre) - R);
          return inside < cortex ? hard : soft;
        },
        DistractorKind::Bone);
    list.push_back({{"centre_mm", point(p0)}, {"normal", point(e[2])}, {"curvature_radius_mm", R}, {"extent_mm", extent}, {"thickness_mm", t}});
  }
  ctx.record["bones"] = list;
}

void applyCalcification(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const VolumeGrid& g = s.grid;
  const VascularTree& tree = *s.tree;
  // Plaque forms in the walls of larger arteries: segments at least min_vessel_radius thick,
  // drawn in proportion to their length.
  const double thinnest = p("min_vessel_radius");
  const PlaceOnTree place(tree, [&](std::int32_t i) { return !tree.isRoot(i) && tree.radius[i] >= thinnest; });
  Json list = Json::array();
  if (!(place.total() > 0) || int(p("count")) == 0) {
    ctx.record["calcifications"] = list;
    return;
  }
  Volume<float> calcium(g);
  for (int n = 0; n < int(p("count")); ++n) {
    const std::int32_t seg = place.draw(ctx.rng.uniform());
    const Vec3 a = tree.position[tree.parent[seg]], b = tree.position[seg];
    const Vec3 axis = (b - a) / tree.length[seg];
    const auto [u, v, unused] = frameAround(axis);
    const double phi = ctx.rng.uniform(0, 2 * M_PI);
    const Vec3 on_axis = a + (b - a) * ctx.rng.uniform();
    const Vec3 c = on_axis + (u * std::cos(phi) + v * std::sin(phi)) * tree.radius[seg];  // on the wall
    const double r = drawBetween(ctx.rng, p("radius_min"), p("radius_max"));
    const double value = drawBetween(ctx.rng, p("density_min"), p("density_max"));
    paintShape(
        s, boxAround(g, c, c, r + 2 * g.spacing_mm.x), [&](const Vec3& q) { return distance(q, c) - r; }, [&](const Vec3&, double) { return value; },
        DistractorKind::Calcification, &calcium);
    list.push_back({{"segment", s.originalSegment(seg)}, {"centre_mm", point(c)}, {"radius_mm", r}, {"density", value}});
  }
  // Blooming: the scanner spreads a dense deposit beyond its size, over the lumen beside it.
  const double bloom = p("blooming");
  if (bloom > 0) gaussianBlur(calcium, Vec3(bloom, bloom, bloom));
  forEachVoxel(g.voxelCount(), [&](std::int64_t q) { s.image.data[q] += calcium.data[q]; });
  ctx.record["calcifications"] = list;
}

}  // namespace

extern const EffectType kDecoys{
    "decoys",
    "structures that are not vessels, placed uniformly in the field of view: ellipsoidal blobs, gently bent tubes (nerves, lymphatics), "
    "thin plates (membranes, bone edges); each adds its intensity where the vessels leave room; written to the distractor label",
    {{"blobs", ParamKind::Count, 0, 100000, "10", "number of blobs"},
     {"blob_radius_min", ParamKind::Length, 0, 1e9, "2 voxel", "least semi-axis of a blob"},
     {"blob_radius_max", ParamKind::Length, 0, 1e9, "6 voxel", "greatest semi-axis of a blob"},
     {"tubes", ParamKind::Count, 0, 100000, "5", "number of tubes"},
     {"tube_radius_min", ParamKind::Length, 0, 1e9, "0.7 voxel", "least tube radius"},
     {"tube_radius_max", ParamKind::Length, 0, 1e9, "2 voxel", "greatest tube radius"},
     {"tube_length_min", ParamKind::Length, 0, 1e9, "0.2 fov", "least tube length"},
     {"tube_length_max", ParamKind::Length, 0, 1e9, "0.6 fov", "greatest tube length"},
     {"plates", ParamKind::Count, 0, 100000, "2", "number of plates"},
     {"plate_thickness_min", ParamKind::Length, 0, 1e9, "1 voxel", "least plate thickness"},
     {"plate_thickness_max", ParamKind::Length, 0, 1e9, "3 voxel", "greatest plate thickness"},
     {"plate_extent_min", ParamKind::Length, 0, 1e9, "0.1 fov", "least side of a plate"},
     {"plate_extent_max", ParamKind::Length, 0, 1e9, "0.4 fov", "greatest side of a plate"},
     {"intensity_min", ParamKind::Intensity, -1e9, 1e9, "0.5 contrast", "least intensity a decoy adds over the tissue"},
     {"intensity_max", ParamKind::Intensity, -1e9, 1e9, "1 contrast", "greatest intensity a decoy adds over the tissue"}},
    applyDecoys,
    /*moves_geometry=*/false,
    /*noise=*/false,
    /*working_bytes_per_voxel=*/4,  // a tube's distances over its box, at most the grid
    /*places_distractors=*/true};

extern const EffectType kBone{
    "bone",
    "bone as caps of spherical shells (skull, vertebral and rib cortex): a dense cortex on both faces, marrow between; CT's "
    "brightest structure beside the contrast-filled vessels; written to the distractor label",
    {{"count", ParamKind::Count, 0, 1000, "1", "number of bones"},
     {"curvature_radius_min", ParamKind::Length, 1e-6, 1e9, "0.5 fov", "least radius of curvature (large: flat)"},
     {"curvature_radius_max", ParamKind::Length, 1e-6, 1e9, "2 fov", "greatest radius of curvature"},
     {"extent_min", ParamKind::Length, 0, 1e9, "0.3 fov", "least diameter of a cap, along its surface"},
     {"extent_max", ParamKind::Length, 0, 1e9, "0.8 fov", "greatest diameter of a cap"},
     {"thickness_min", ParamKind::Length, 0, 1e9, "4 voxel", "least thickness of the shell"},
     {"thickness_max", ParamKind::Length, 0, 1e9, "8 voxel", "greatest thickness of the shell"},
     {"cortex_thickness", ParamKind::Length, 0, 1e9, "1.5 voxel", "thickness of the cortex on each face"},
     {"cortex", ParamKind::Intensity, -1e9, 1e9, "3 contrast", "intensity the cortex adds over the tissue (CT: 1000-1800 HU)"},
     {"marrow", ParamKind::Intensity, -1e9, 1e9, "0.8 contrast", "intensity the marrow adds over the tissue (CT: 200-400 HU)"}},
    applyBone,
    /*moves_geometry=*/false,
    /*noise=*/false,
    /*working_bytes_per_voxel=*/0,
    /*places_distractors=*/true};

extern const EffectType kCalcification{
    "calcification",
    "calcified plaque on the walls of vessels at least min_vessel_radius thick, spread by blooming (a Gaussian of that width) "
    "over the lumen beside it, as CT shows it; written to the distractor label at its true extent",
    {{"count", ParamKind::Count, 0, 100000, "3", "number of deposits, placed in proportion to vessel length"},
     {"radius_min", ParamKind::Length, 0, 1e9, "0.5 voxel", "least radius of a deposit"},
     {"radius_max", ParamKind::Length, 0, 1e9, "1.5 voxel", "greatest radius of a deposit"},
     {"density_min", ParamKind::Intensity, -1e9, 1e9, "2 contrast", "least intensity a deposit adds (CT: 400-1500 HU)"},
     {"density_max", ParamKind::Intensity, -1e9, 1e9, "4 contrast", "greatest intensity a deposit adds"},
     {"blooming", ParamKind::Length, 0, 1e9, "0.7 voxel", "Gaussian σ of the blooming (0: none)", 0, 0.5},
     {"min_vessel_radius", ParamKind::Length, 0, 1e9, "0", "thinnest vessel that takes a deposit"}},
    applyCalcification,
    /*moves_geometry=*/false,
    /*noise=*/false,
    /*working_bytes_per_voxel=*/4,
    /*places_distractors=*/true};

}  // namespace angiosynth
