// Backgrounds, distractors and modality artefacts, each checked by the property that defines it,
// measured on the effect's output: a decoy's volume and level and its own label, bone's two
// levels, the blooming of a calcification, Voronoi cells, compartment levels, the inflow decay
// constant recovered along the graph, slab steps, OCTA tails and shadows, speckle statistics,
// partial Fourier's one-axis blur; and for every effect that leaves geometry alone, the labels
// of the clean run and the same bytes on one thread as on two.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <set>

#include "cli_run.hpp"
#include "degrade/effect.hpp"
#include "degrade_support.hpp"
#include "raster/ground_truth.hpp"
#include "test_support.hpp"

namespace angiosynth {
namespace {

namespace fs = std::filesystem;

using test::degradeWith;
using test::flatTruth;
using test::profileFrom;

const char* const kLevels = "background = 100\nvessel = 300\ndtype = \"float32\"\n";

// A decoy blob of fixed semi-axes on an empty 64³ grid: its labelled voxels hold its volume
// (4/3·π·abc within 3 %), the image there is the background plus its intensity, nothing else is
// labelled or changed, and the record names it.
TEST(Realism, DecoyBlobHasItsVolumeLevelAndOwnLabel) {
  const auto gt = flatTruth(64);
  const auto d = degradeWith(
      profileFrom("decoy_blob",
                  std::string(kLevels) +
                      "[[effect]]\ntype = \"decoys\"\nblobs = 1\ntubes = 0\nplates = 0\nblob_radius_min = \"6 mm\"\nblob_radius_max = \"6 mm\"\n"
                      "intensity_min = 50\nintensity_max = 50\n"),
      gt);
  ASSERT_TRUE(d.distractors);
  std::int64_t labelled = 0, other = 0;
  double inside = 0;
  for (std::size_t v = 0; v < d.image.data.size(); ++v) {
    if (d.distractors->data[v] == std::uint8_t(DistractorKind::Blob)) {
      ++labelled;
      inside += d.image.data[v];
    } else if (d.distractors->data[v] != 0) {
      ++other;
    }
  }
  // The blob may be cut by the grid's faces: compare with the volume of its part inside.
  const auto& rec = d.record["effects"][0]["decoys"][0];
  ASSERT_EQ(rec["kind"], "blob");
  const Vec3 c(rec["centre_mm"][0], rec["centre_mm"][1], rec["centre_mm"][2]);
  std::int64_t expected = 0;
  for (std::int64_t k = 0; k < 64; ++k)
    for (std::int64_t j = 0; j < 64; ++j)
      for (std::int64_t i = 0; i < 64; ++i) expected += distance(gt.fraction.grid.centre(i, j, k), c) < 6;
  ASSERT_GT(expected, 100);
  EXPECT_NEAR(double(labelled), double(expected), 0.03 * expected);
  EXPECT_EQ(other, 0);
  EXPECT_GT(inside / labelled, 100 + 0.9 * 50);  // fully covered voxels at 150, the rim at least half
  EXPECT_EQ(d.record["distractor_voxels"]["blob"], labelled);
}

// Decoys on a real tree never take a vessel voxel: the distractor label is background in the mask.
TEST(Realism, DistractorsAreNeverVesselVoxels) {
  const auto ex = test::vascusynthExample(300, 3);
  const VascularTree tree = test::grow(ex);
  const VolumeGrid g = test::cubeGrid(64, 40.0 / 64);
  const auto gt = rasterizeGroundTruth(tree, g, RasterOptions{2});
  const auto d = degradeWith(profileFrom("decoys_tree", std::string(kLevels) + "[[effect]]\ntype = \"decoys\"\nblobs = 20\ntubes = 20\nplates = 10\n"
                                                                               "[[effect]]\ntype = \"bone\"\ncount = 2\n"
                                                                               "[[effect]]\ntype = \"calcification\"\ncount = 20\n"),
                             gt, tree, 5);
  ASSERT_TRUE(d.distractors);
  std::set<int> kinds;
  std::int64_t overlap = 0;
  for (std::size_t v = 0; v < gt.mask.data.size(); ++v) {
    if (d.distractors->data[v]) kinds.insert(d.distractors->data[v]);
    overlap += d.distractors->data[v] && gt.mask.data[v];
  }
  EXPECT_EQ(overlap, 0);
  EXPECT_EQ(kinds, (std::set<int>{1, 2, 3, 4, 5}));
}

// A flat bone (curvature radius 10⁶ mm) 8 voxels thick with a cortex of 2 voxels on each face:
// about half its voxels at the cortex's level, the middle at the marrow's.
TEST(Realism, BoneHasCortexOnBothFacesAndMarrowBetween) {
  const auto gt = flatTruth(64);
  const auto d = degradeWith(
      profileFrom("bone_flat", std::string(kLevels) +
                                   "[[effect]]\ntype = \"bone\"\ncount = 1\ncurvature_radius_min = \"1000000 mm\"\n"
                                   "curvature_radius_max = \"1000000 mm\"\nthickness_min = \"8 mm\"\nthickness_max = \"8 mm\"\n"
                                   "extent_min = \"40 mm\"\nextent_max = \"40 mm\"\ncortex_thickness = \"2 mm\"\ncortex = 1200\nmarrow = 250\n"),
      gt);
  ASSERT_TRUE(d.distractors);
  std::int64_t bone = 0, cortex = 0, marrow = 0;
  for (std::size_t v = 0; v < d.image.data.size(); ++v) {
    if (d.distractors->data[v] != std::uint8_t(DistractorKind::Bone)) continue;
    ++bone;
    cortex += std::fabs(d.image.data[v] - 1300) < 1;
    marrow += std::fabs(d.image.data[v] - 350) < 1;
  }
  ASSERT_GT(bone, 1000);
  // Fully covered voxels only (the rim is partial): cortex 2 + 2 of 8 voxels, marrow 4 of 8.
  EXPECT_GT(double(cortex) / bone, 0.25);
  EXPECT_GT(double(marrow) / bone, 0.3);
  EXPECT_NEAR(double(cortex) / marrow, 2.0 / 4.0 * (4.0 / 2.0), 0.6);  // both faces' cortex against the marrow: about 1
}

// Blooming: a deposit's signal spreads as a ball of radius r convolved with a Gaussian σ, so its
// second moment per axis is r²/5 + σ² and its total is kept.
TEST(Realism, CalcificationBloomsByItsGaussian) {
  const auto ex = test::vascusynthExample(300, 3);
  const VascularTree tree = test::grow(ex);
  const VolumeGrid g = test::cubeGrid(80, 0.5);
  const auto gt = rasterizeGroundTruth(tree, g, RasterOptions{2});
  const auto make = [&](const char* bloom) {
    return degradeWith(profileFrom(std::string("calc_") + (bloom[0] == '0' ? "sharp" : "bloom"),
                                   std::string(kLevels) +
                                       "[[effect]]\ntype = \"calcification\"\ncount = 1\nradius_min = \"1.5 mm\"\nradius_max = \"1.5 mm\"\n"
                                       "density_min = 800\ndensity_max = 800\nmin_vessel_radius = \"0.3 mm\"\nblooming = \"" +
                                       bloom + "\"\n"),
                       gt, tree, 9);
  };
  const auto base = degradeWith(profileFrom("calc_none", kLevels), gt, tree, 9);
  for (const char* bloom : {"0 mm", "1 mm"}) {
    const auto d = make(bloom);
    const auto& rec = d.record["effects"][0]["calcifications"][0];
    const Vec3 c(rec["centre_mm"][0], rec["centre_mm"][1], rec["centre_mm"][2]);
    double w = 0, m2 = 0;
    for (std::int64_t k = 0; k < 80; ++k)
      for (std::int64_t j = 0; j < 80; ++j)
        for (std::int64_t i = 0; i < 80; ++i) {
          const std::int64_t v = g.flat(i, j, k);
          const double x = d.image.data[v] - base.image.data[v];
          const Vec3 r = g.centre(i, j, k) - c;
          w += x;
          m2 += x * dot(r, r) / 3;
        }
    const double sigma = std::atof(bloom);
    // The part of the ball in the lumen adds nothing (plaque sits in the wall): the moments are
    // those of the ball's outer part, close to a ball's; the total within the ball's volume.
    EXPECT_LT(w, 800 * 4.0 / 3 * M_PI * 1.5 * 1.5 * 1.5 / 0.125 * 1.05) << bloom;
    EXPECT_GT(w, 800 * 4.0 / 3 * M_PI * 1.5 * 1.5 * 1.5 / 0.125 * 0.3) << bloom;
    const double want = 1.5 * 1.5 / 5 + sigma * sigma;
    EXPECT_NEAR(m2 / w, want, 0.35 * want) << bloom;
    if (sigma > 0) { EXPECT_GT(m2 / w, 1.5 * 1.5 / 5 + 0.6 * sigma * sigma); }
  }
}

// Voronoi cells: each voxel takes its nearest seed's level, so the image holds about one level
// per lattice cell (8³ = 512 cells and the outer seeds nearest to border voxels), their spread
// is the amplitude, and walls brighten the voxels between cells.
TEST(Realism, VoronoiCellsAreConstantWithTheirAmplitudeAndWalls) {
  const auto gt = flatTruth(64);
  const auto d =
      degradeWith(profileFrom("cells", std::string(kLevels) + "[[effect]]\ntype = \"voronoi\"\ncell_size = \"8 mm\"\namplitude = 10\n"), gt);
  std::set<float> levels(d.image.data.begin(), d.image.data.end());
  EXPECT_GT(levels.size(), 450u);
  EXPECT_LT(levels.size(), 1400u);
  std::vector<double> values(levels.begin(), levels.end());
  const double mean = std::accumulate(values.begin(), values.end(), 0.0) / values.size();
  double var = 0;
  for (double v : values) var += (v - mean) * (v - mean);
  EXPECT_NEAR(std::sqrt(var / (values.size() - 1)), 10, 1.0);
  EXPECT_NEAR(mean, 100, 1.5);
  const auto walled = degradeWith(
      profileFrom("cells_walls", std::string(kLevels) +
                                     "[[effect]]\ntype = \"voronoi\"\ncell_size = \"8 mm\"\namplitude = 0\nwall = 40\nwall_thickness = \"1 mm\"\n"),
      gt);
  std::int64_t wall = 0;
  for (float v : walled.image.data) wall += v > 120;
  // Walls one voxel thick around cells 8 voxels across: about 3/8 of a cell's volume.
  const double share = double(wall) / walled.image.data.size();
  EXPECT_GT(share, 0.15);
  EXPECT_LT(share, 0.5);
}

// Compartments with sharp borders: the image holds exactly the recorded levels, each on a
// sizeable region.
TEST(Realism, CompartmentsHoldTheirRecordedLevels) {
  const auto gt = flatTruth(48);
  const auto d =
      degradeWith(profileFrom("organs", std::string(kLevels) + "[[effect]]\ntype = \"compartments\"\ncount = 4\ncontrast = 30\nedge = 0\n"), gt);
  const auto& rec = d.record["effects"][0]["levels"];
  ASSERT_EQ(rec.size(), 4u);
  std::map<float, std::int64_t> seen;
  for (float v : d.image.data) ++seen[v];
  EXPECT_LE(seen.size(), 4u);
  EXPECT_GE(seen.size(), 2u);
  for (const auto& [level, count] : seen) {
    bool recorded = false;
    for (const auto& l : rec) recorded |= std::fabs(100 + l.get<double>() - level) < 1e-3;
    EXPECT_TRUE(recorded) << level;
    EXPECT_GT(count, 48 * 48 * 48 / 100) << level;
  }
}

// Inflow saturation along a real tree: on every centreline voxel fully inside a vessel the
// signal is contrast × exp(−D/length), D the path from the root computed here from the parent
// links; the fitted decay length recovers the profile's within 1 %. With slow flow, D weights
// each segment by the root's velocity over its own (flow / area), and thin vessels lose more.
TEST(Realism, InflowDecayConstantIsRecoveredAlongTheGraph) {
  const auto ex = test::vascusynthExample(300, 3);
  const VascularTree tree = test::grow(ex);
  const VolumeGrid g = test::cubeGrid(100, 0.4);
  const auto gt = rasterizeGroundTruth(tree, g, RasterOptions{2});
  for (const bool slow : {false, true}) {
    // D of each node, by walking up to the root.
    const auto velocity = [&](std::int32_t s) { return tree.flow[s] / (M_PI * tree.radius[s] * tree.radius[s]); };
    const double v_root = velocity(tree.rootSegment());
    std::vector<double> D(tree.nodeCount(), 0);
    for (std::int32_t n = 0; n < tree.nodeCount(); ++n)
      for (std::int32_t s = n; !tree.isRoot(s); s = tree.parent[s]) D[n] += tree.length[s] * (slow ? v_root / velocity(s) : 1);
    const auto d =
        degradeWith(profileFrom(slow ? "inflow_slow" : "inflow_plain", std::string(kLevels) + "[[effect]]\ntype = \"inflow\"\nlength = \"25 mm\"\n" +
                                                                           "slow_flow = " + (slow ? "1" : "0") + "\n"),
                    gt, tree);
    double sxx = 0, sxy = 0;
    int used = 0;
    double worst = 0;
    for (std::int64_t v = 0; v < g.voxelCount(); ++v) {
      if (!gt.centerline.data[v] || gt.fraction.data[v] < 1) continue;
      const std::int32_t seg = std::int32_t(gt.instances.data[v]);
      if (seg <= 0) continue;
      // The voxel's distance: its projection on its segment.
      const std::int64_t i = v % 100, j = (v / 100) % 100, k = v / 10000;
      const Vec3 a = tree.position[tree.parent[seg]], b = tree.position[seg];
      const double along = std::clamp(dot(g.centre(i, j, k) - a, b - a) / tree.length[seg], 0.0, tree.length[seg]);
      const double x = D[tree.parent[seg]] + along * (D[seg] - D[tree.parent[seg]]) / tree.length[seg];
      const double y = std::log((d.image.data[v] - 100) / 200);
      worst = std::max(worst, std::fabs(y + x / 25));
      sxx += x * x, sxy += x * y, ++used;
    }
    ASSERT_GT(used, 300);
    EXPECT_NEAR(-sxx / sxy, 25, 0.25) << (slow ? "slow flow" : "plain");
    EXPECT_LT(worst, 0.2) << "a voxel far off the law";
  }
}

// Slabs 10 voxels thick along z over a uniform vessel column: the vessel signal falls linearly
// by `drop` across each slab and steps back up at its border; tissue is edge_loss darker at the faces.
TEST(Realism, SlabsStepTheSignalAtTheirBorders) {
  auto gt = flatTruth({8, 8, 40});
  for (std::int64_t k = 0; k < 40; ++k) gt.fraction.at(4, 4, k) = 1;
  const auto d = degradeWith(
      profileFrom("slabs", std::string(kLevels) + "[[effect]]\ntype = \"slab\"\nthickness = \"10 mm\"\ndrop = 0.4\nedge_loss = 0.2\n"), gt);
  EXPECT_EQ(d.record["effects"][0]["slabs"], 4);
  for (std::int64_t k = 0; k < 40; ++k) {
    const double zeta = (k % 10 + 0.5) / 10;
    EXPECT_NEAR(d.image.at(4, 4, k), 100 * (1 - 0.2 * (2 * zeta - 1) * (2 * zeta - 1)) + 200 * (1 - 0.4 * zeta), 1e-3) << k;
    EXPECT_NEAR(d.image.at(0, 0, k), 100 * (1 - 0.2 * (2 * zeta - 1) * (2 * zeta - 1)), 1e-3) << k;
  }
  // The venetian-blind step at each border: 0.4 × 200 × 9/10.
  for (std::int64_t k : {10, 20, 30}) EXPECT_NEAR(d.image.at(4, 4, k) - d.image.at(4, 4, k - 1), 0.4 * 200 * 0.9, 1e-3);
}

// OCTA: a vessel plane at depth 10 of a 40-voxel column: below it, the tail falls by e over
// tail_length (fitted from the image: within 1 %), and the tissue keeps exp(−1 mm / shadow_length).
TEST(Realism, ProjectionTailsDecayByTheirLengthAndShadowsAttenuate) {
  auto gt = flatTruth({4, 4, 40});
  for (std::int64_t j = 0; j < 4; ++j)
    for (std::int64_t i = 0; i < 4; ++i) gt.fraction.at(i, j, 10) = 1;
  const auto d = degradeWith(
      profileFrom("octa", std::string(kLevels) +
                              "[[effect]]\ntype = \"projection\"\ntail = 0.5\ntail_length = \"6 mm\"\nshadow_length = \"3.3333333333333 mm\"\n"),
      gt);
  const double kept = std::exp(-0.3);
  for (std::int64_t k = 0; k < 10; ++k) EXPECT_NEAR(d.image.at(1, 1, k), 100, 1e-3);
  EXPECT_NEAR(d.image.at(1, 1, 10), 300, 1e-3);
  double sxx = 0, sxy = 0;
  for (std::int64_t k = 11; k < 40; ++k) {
    const double x = k - 10, y = std::log((d.image.at(1, 1, k) - 100 * kept) / (0.5 * 200));
    sxx += x * x, sxy += x * y;
  }
  EXPECT_NEAR(-sxx / sxy, 6, 0.06);
  EXPECT_NEAR(d.image.at(1, 1, 39) - 0.5 * 200 * std::exp(-29.0 / 6), 100 * kept, 1e-3);
}

// Speckle of 4 looks on a uniform image: mean kept, variance I²/4 (Gamma(4, 1/4)), never negative.
TEST(Realism, SpeckleHasGammaMeanAndVariance) {
  const auto gt = flatTruth(64);
  const auto d = degradeWith(profileFrom("speckle4", std::string(kLevels) + "[[effect]]\ntype = \"speckle\"\nlooks = 4\n"), gt);
  double s = 0, s2 = 0;
  float lowest = INFINITY;
  for (float v : d.image.data) s += v, s2 += double(v) * v, lowest = std::min(lowest, v);
  const double n = double(d.image.data.size()), mean = s / n, var = s2 / n - mean * mean;
  EXPECT_NEAR(mean, 100, 0.3);
  EXPECT_NEAR(var, 100.0 * 100 / 4, 0.02 * 2500);
  EXPECT_GE(lowest, 0);
}

// Partial Fourier along y: a pattern constant along y keeps every value; a plane across y (all
// its k-space along y) loses resolution: its peak falls and its width along y grows.
TEST(Realism, PartialFourierBlursAlongItsAxisOnly) {
  auto gt = flatTruth(32);
  for (std::int64_t k = 0; k < 32; ++k)
    for (std::int64_t j = 0; j < 32; ++j) gt.fraction.at(16, j, k) = 1;  // a plane normal to x
  const Profile pf = profileFrom("pf", std::string(kLevels) + "[[effect]]\ntype = \"partial_fourier\"\naxis = 1\nshare = 0.625\n");
  const auto along = degradeWith(pf, gt);
  for (std::int64_t i = 0; i < 32; ++i) EXPECT_NEAR(along.image.at(i, 5, 5), i == 16 ? 300 : 100, 1e-2) << i;
  auto across = flatTruth(32);
  for (std::int64_t k = 0; k < 32; ++k)
    for (std::int64_t i = 0; i < 32; ++i) across.fraction.at(i, 16, k) = 1;  // a plane normal to y
  const auto d = degradeWith(pf, across);
  EXPECT_LT(d.image.at(5, 16, 5), 100 + 0.8 * 200);
  EXPECT_GT(std::fabs(d.image.at(5, 15, 5) - 100) + std::fabs(d.image.at(5, 17, 5) - 100), 0.1 * 200);
}

// Texture on the vessels too (vesselFM's foreground texture): with vessel_share 1 a grid full of
// vessel takes exactly the field an empty grid takes; with 0 (the default), none of it.
TEST(Realism, TextureReachesTheVesselsByItsVesselShare) {
  const auto empty = flatTruth(32);
  auto full = flatTruth(32);
  std::fill(full.fraction.data.begin(), full.fraction.data.end(), 1.0f);
  const auto textured = [](const char* share) {
    return profileFrom(std::string("texture_share_") + share,
                       std::string(kLevels) + "[[effect]]\ntype = \"texture\"\namplitude = 20\nvessel_share = " + share + "\n");
  };
  const auto tissue = degradeWith(textured("1"), empty), vessel = degradeWith(textured("1"), full), plain = degradeWith(textured("0"), full);
  double spread = 0;
  for (std::size_t v = 0; v < tissue.image.data.size(); ++v) {
    ASSERT_NEAR(vessel.image.data[v] - 300, tissue.image.data[v] - 100, 1e-3);
    ASSERT_EQ(plain.image.data[v], 300.0f);
    spread = std::max(spread, std::fabs(double(tissue.image.data[v]) - 100));
  }
  EXPECT_GT(spread, 20);
}

// Every effect that leaves geometry alone, all in one profile through `generate`: mask,
// centreline, radius, instances and classes are the clean run's bytes, and the image and the
// distractor label the same on one thread as on two.
TEST(Realism, EveryIntensityEffectKeepsTheCleanLabelsOnAnyThreadCount) {
  const fs::path dir = freshTestDir("angiosynth_realism_labels_");
  std::string profile = "description = \"every effect\"\nbackground = 100\nvessel = 400\n";
  int effects = 0;
  for (const EffectType* t : effectTypes()) {
    if (t->moves_geometry) continue;
    profile += exampleEffectToml(*t);
    ++effects;
  }
  EXPECT_GE(effects, 25);
  std::ofstream(dir / "all.toml") << profile;
  std::ofstream(dir / "p.toml") << test::kSmallCcoSample;
  ASSERT_EQ(run("generate p.toml --out plain --no-profiles --quiet", dir).code, 0);
  const auto r = run("generate p.toml --out all --profile all.toml --quiet", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"mask.nii.gz", "centerline.nii.gz", "radius.nii.gz", "instances.nii.gz", "classes.nii.gz"})
    if (fs::exists(dir / "plain" / f)) { EXPECT_EQ(slurp(dir / "plain" / f), slurp(dir / "all" / f)) << f; }
  ASSERT_EQ(run("generate p.toml --out all1 --profile all.toml --threads 1 --quiet", dir).code, 0);
  for (const char* f : {"image_all.nii.gz", "distractors_all.nii.gz"}) {
    ASSERT_TRUE(fs::exists(dir / "all" / f)) << f;
    EXPECT_EQ(slurp(dir / "all" / f), slurp(dir / "all1" / f)) << f;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace angiosynth

namespace angiosynth {
namespace {

struct BackgroundStats {
  double cnr = 0;         // (thick vessels − background) / background sd
  double structured = 0;  // share of the background's variance at scales of 4 voxels and more
  double vessel_mean = 0, background_mean = 0, background_sd = 0;
};

// Vessel: centreline voxels of vessels at least 2 voxels in radius, fully inside them. Background:
// voxels more than 3 voxels from the mask and from every distractor (where a radiologist would
// put a region of interest: off the PSF's halo of bone). The structured share compares
// the variance of 4³ block means with what white noise would leave of it (var / 64).
BackgroundStats measure(const DegradedImage& d, const GroundTruthVolumes& gt) {
  const VolumeGrid& g = gt.mask.grid;
  const double h = g.spacing_mm.x;
  Volume<std::uint8_t> near(g);
  for (std::int64_t k = 0; k < g.dims[2]; ++k)
    for (std::int64_t j = 0; j < g.dims[1]; ++j)
      for (std::int64_t i = 0; i < g.dims[0]; ++i) {
        const std::int64_t q = g.flat(i, j, k);
        if (!gt.mask.data[q] && !(d.distractors && d.distractors->data[q])) continue;
        for (std::int64_t c = std::max<std::int64_t>(0, k - 3); c <= std::min<std::int64_t>(g.dims[2] - 1, k + 3); ++c)
          for (std::int64_t b = std::max<std::int64_t>(0, j - 3); b <= std::min<std::int64_t>(g.dims[1] - 1, j + 3); ++b)
            for (std::int64_t a = std::max<std::int64_t>(0, i - 3); a <= std::min<std::int64_t>(g.dims[0] - 1, i + 3); ++a) near.at(a, b, c) = 1;
      }
  double sv = 0, sb = 0, sb2 = 0;
  std::int64_t nv = 0, nb = 0;
  for (std::int64_t v = 0; v < g.voxelCount(); ++v) {
    const double x = d.image.data[v];
    if (gt.centerline.data[v] && gt.radius.data[v] >= 2 * h && gt.fraction.data[v] >= 1) sv += x, ++nv;
    if (!near.data[v]) sb += x, sb2 += x * x, ++nb;
  }
  BackgroundStats s;
  s.vessel_mean = sv / std::max<std::int64_t>(nv, 1);
  s.background_mean = sb / std::max<std::int64_t>(nb, 1);
  s.background_sd = std::sqrt(std::max(0.0, sb2 / std::max<std::int64_t>(nb, 1) - s.background_mean * s.background_mean));
  s.cnr = (s.vessel_mean - s.background_mean) / s.background_sd;
  // Blocks wholly in the background.
  double bm = 0, bm2 = 0;
  std::int64_t blocks = 0;
  for (std::int64_t k = 0; k + 4 <= g.dims[2]; k += 4)
    for (std::int64_t j = 0; j + 4 <= g.dims[1]; j += 4)
      for (std::int64_t i = 0; i + 4 <= g.dims[0]; i += 4) {
        double m = 0;
        bool clear = true;
        for (std::int64_t c = k; c < k + 4 && clear; ++c)
          for (std::int64_t b = j; b < j + 4 && clear; ++b)
            for (std::int64_t a = i; a < i + 4; ++a) {
              const std::int64_t v = g.flat(a, b, c);
              if (near.data[v]) {
                clear = false;
                break;
              }
              m += d.image.data[v];
            }
        if (!clear) continue;
        m /= 64;
        bm += m, bm2 += m * m, ++blocks;
      }
  const double var = s.background_sd * s.background_sd;
  const double block_var = bm2 / blocks - (bm / blocks) * (bm / blocks);
  s.structured = (block_var - var / 64) / var;
  return s;
}

// Each modality profile on a grown tree (100³ at 0.4 mm) over three seeds: the large vessels'
// contrast-to-noise ratio lies in the band its cited levels and noise give (docs/degradation.md),
// and its background has structure (tissue, cells, compartments) beyond white noise, which
// VascuSynth's profile, white noise only, does not (its CNR is 255 over the sd of N(0, 20²)
// clamped at 0, about 20).
TEST(RealismProfiles, ModalityProfilesHaveTheirContrastToNoiseAndAStructuredBackground) {
  const auto ex = test::vascusynthExample(1000, 2);
  const VascularTree tree = test::grow(ex);
  const VolumeGrid g = test::cubeGrid(100, 0.4);
  const auto gt = rasterizeGroundTruth(tree, g, RasterOptions{2});
  const std::map<std::string, std::pair<double, double>> band{
      {"cta", {5, 45}}, {"tof_mra", {4, 45}}, {"two_photon", {5, 60}}, {"octa", {3, 40}}, {"vascusynth", {18, 23}}};
  for (const auto& [name, range] : band) {
    const Profile p = readProfileToml(test::sourceDir() / "noise_profiles" / (name + ".toml"));
    for (std::uint64_t seed : {1, 2, 3}) {
      const BackgroundStats s = measure(degradeWith(p, gt, tree, seed), gt);
      EXPECT_GE(s.cnr, range.first) << name << " seed " << seed;
      EXPECT_LE(s.cnr, range.second) << name << " seed " << seed;
      if (name == "vascusynth") {
        EXPECT_LT(std::fabs(s.structured), 0.01) << name;
      } else {
        EXPECT_GT(s.structured, 0.02) << name << " seed " << seed;
      }
      std::printf("%s seed %llu: CNR %.1f (vessel %.1f, background %.1f ± %.1f), structured share %.3f\n", name.c_str(), (unsigned long long)seed,
                  s.cnr, s.vessel_mean, s.background_mean, s.background_sd, s.structured);
    }
  }
}

}  // namespace
}  // namespace angiosynth
