// Degradation: the statistics of every noise model, the PSF of the blur, impulse rates,
// dropouts, determinism, profiles and noise files, and the consistency of warped labels and
// graphs with the warped image.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numeric>

#include "core/distributions.hpp"
#include "core/error.hpp"
#include "degrade/degrade.hpp"
#include "degrade/warp.hpp"
#include "pipeline/volume_outputs.hpp"
#include "degrade_support.hpp"
#include "test_support.hpp"

namespace angiosynth {
namespace {

namespace fs = std::filesystem;

using test::flatTruth;
using test::kNoTree;
using test::profileFrom;
using test::writeTemp;

// n³ voxels over the example's 40 mm map, voxel centres at (i + ½)·40/n.
VolumeGrid mapGrid(int n) { return test::cubeGrid(n, 40.0 / n); }

struct Moments {
  double mean = 0, sd = 0;
};
Moments moments(const VoxelBuffer<float>& v) {
  double s = 0, s2 = 0;
  for (float x : v) s += x;
  const double m = s / v.size();
  for (float x : v) s2 += (x - m) * (x - m);
  return {m, std::sqrt(s2 / (v.size() - 1))};
}

TEST(Degrade, GaussianNoiseHasItsMeanAndSigma) {
  const auto gt = flatTruth(64);
  const auto d = test::degradeWith(profileFrom("g", "background = 100\n[[effect]]\ntype = \"gaussian\"\nmean = 5\nsigma = 20\n"), gt, kNoTree);
  const auto m = moments(d.image.data);
  const double n = double(d.image.data.size());
  EXPECT_NEAR(m.mean, 105, 5 * 20 / std::sqrt(n));
  EXPECT_NEAR(m.sd, 20, 5 * 20 / std::sqrt(2 * n));
  // Shape: the share within one sigma is that of a normal law.
  const double within = std::count_if(d.image.data.begin(), d.image.data.end(), [](float x) { return std::fabs(x - 105) < 20; }) / n;
  EXPECT_NEAR(within, 0.682689, 5 * std::sqrt(0.6827 * 0.3173 / n));
}

TEST(Degrade, UniformNoiseHasItsBoundsMeanAndVariance) {
  const auto gt = flatTruth(64);
  const auto d = test::degradeWith(profileFrom("u", "[[effect]]\ntype = \"uniform\"\nlow = -10\nhigh = 30\n"), gt, kNoTree);
  const auto m = moments(d.image.data);
  const double n = double(d.image.data.size()), sd = 40 / std::sqrt(12.0);
  EXPECT_NEAR(m.mean, 10, 5 * sd / std::sqrt(n));
  EXPECT_NEAR(m.sd, sd, 0.01 * sd);
  EXPECT_GE(*std::min_element(d.image.data.begin(), d.image.data.end()), -10.0f);
  EXPECT_LE(*std::max_element(d.image.data.begin(), d.image.data.end()), 30.0f);
}

TEST(Degrade, ImpulseRatesMatchTheirProbabilities) {
  const auto gt = flatTruth(64);
  const auto d = test::degradeWith(profileFrom("i",
                                               "background = 100\nvessel = 200\n[[effect]]\ntype = \"impulse\"\nsalt_probability = 0.03\n"
                                               "pepper_value = 0\npepper_probability = 0.05\n"),
                                   gt, kNoTree);
  const double n = double(d.image.data.size());
  const double salt = std::count(d.image.data.begin(), d.image.data.end(), 200.0f) / n;
  const double pepper = std::count(d.image.data.begin(), d.image.data.end(), 0.0f) / n;
  EXPECT_NEAR(salt, 0.03, 5 * std::sqrt(0.03 * 0.97 / n));
  EXPECT_NEAR(pepper, 0.05, 5 * std::sqrt(0.05 * 0.95 / n));
  EXPECT_EQ(std::count(d.image.data.begin(), d.image.data.end(), 100.0f) + std::lround(n * (salt + pepper)), std::lround(n));
}

TEST(Degrade, RicianNoiseOnZeroSignalFollowsTheRayleighLaw) {
  const auto gt = flatTruth(64);
  const double sigma = 10;
  const auto d = test::degradeWith(profileFrom("r", "[[effect]]\ntype = \"rician\"\nsigma = 10\n"), gt, kNoTree);
  std::vector<float> x(d.image.data.begin(), d.image.data.end());
  std::sort(x.begin(), x.end());
  const double n = double(x.size());
  // Kolmogorov–Smirnov against F(x) = 1 − exp(−x²/2σ²); 1.63/√n is the 1 % critical value.
  double ks = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double f = 1 - std::exp(-double(x[i]) * x[i] / (2 * sigma * sigma));
    ks = std::max({ks, std::fabs(f - double(i) / n), std::fabs(f - double(i + 1) / n)});
  }
  EXPECT_LT(ks, 1.63 / std::sqrt(n));
  const auto m = moments(d.image.data);
  EXPECT_NEAR(m.mean, sigma * std::sqrt(M_PI / 2), 5 * sigma * 0.655 / std::sqrt(n));
  EXPECT_NEAR(m.sd, sigma * std::sqrt((4 - M_PI) / 2), 0.01 * sigma);
}

TEST(Degrade, PoissonNoiseHasMeanAndVarianceLambdaOnBothSamplers) {
  const auto gt = flatTruth(48);
  for (double lambda : {3.0, 40.0}) {  // Knuth's product below 10, PTRS above
    const auto p = profileFrom("p", "background = " + std::to_string(lambda) + "\n[[effect]]\ntype = \"poisson\"\n");
    const auto d = test::degradeWith(p, gt, kNoTree);
    const auto m = moments(d.image.data);
    const double n = double(d.image.data.size());
    EXPECT_NEAR(m.mean, lambda, 5 * std::sqrt(lambda / n)) << lambda;
    EXPECT_NEAR(m.sd * m.sd, lambda, 0.02 * lambda) << lambda;
    const double zeros = std::count(d.image.data.begin(), d.image.data.end(), 0.0f) / n;
    const double p0 = std::exp(-lambda);
    EXPECT_NEAR(zeros, p0, 5 * std::sqrt(p0 * (1 - p0) / n) + 1e-12) << lambda;
    for (float v : d.image.data) ASSERT_EQ(v, std::round(v));  // counts
  }
}

TEST(Degrade, BlurredVoxelHasThePsfSigmaOnEachAxis) {
  // Anisotropic voxels; σ given in mm must come out in mm.
  auto gt = flatTruth(41, Vec3(0.5, 0.8, 1.0));
  gt.fraction.at(20, 20, 20) = 1;
  const auto d =
      test::degradeWith(profileFrom("b", "vessel = 1\n[[effect]]\ntype = \"blur\"\nsigma = [\"1 mm\", \"1.6 mm\", \"3 mm\"]\n"), gt, kNoTree);
  double sum = 0, m2[3] = {0, 0, 0};
  const auto& g = d.image.grid;
  for (int k = 0; k < 41; ++k)
    for (int j = 0; j < 41; ++j)
      for (int i = 0; i < 41; ++i) {
        const double w = d.image.at(i, j, k);
        sum += w;
        m2[0] += w * std::pow((i - 20) * g.spacing_mm.x, 2);
        m2[1] += w * std::pow((j - 20) * g.spacing_mm.y, 2);
        m2[2] += w * std::pow((k - 20) * g.spacing_mm.z, 2);
      }
  EXPECT_NEAR(sum, 1, 1e-5);
  const double want[3] = {1, 1.6, 3};
  for (int ax = 0; ax < 3; ++ax) EXPECT_NEAR(std::sqrt(m2[ax] / sum), want[ax], 0.005 * want[ax]) << "axis " << ax;
}

TEST(Degrade, SameSeedSameImageWhateverTheThreadsAndStreamsDiffer) {
  const auto ex = test::vascusynthExample(300, 3);
  const VascularTree tree = test::grow(ex);
  const VolumeGrid g = mapGrid(64);
  const auto gt = rasterizeGroundTruth(tree, g, RasterOptions{2});
  const Profile p = readProfileToml(test::sourceDir() / "noise_profiles/domain_randomisation.toml");
  Profile all = p;  // every effect applied
  for (auto& e : all.effects) e.probability.reset();
  DegradedImage one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = test::degradeWith(all, gt, tree, 11);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = test::degradeWith(all, gt, tree, 11);
  }
  ASSERT_EQ(one.image.data.size(), two.image.data.size());
  EXPECT_EQ(std::memcmp(one.image.data.data(), two.image.data.data(), one.image.data.size() * 4), 0);
  ASSERT_TRUE(one.labels && two.labels);
  EXPECT_EQ(one.labels->mask.data, two.labels->mask.data);
  EXPECT_EQ(one.labels->instances.data, two.labels->instances.data);
  EXPECT_EQ(one.record.dump(), two.record.dump());
  const auto other_seed = test::degradeWith(all, gt, tree, 12);
  EXPECT_NE(other_seed.record["effects"][0].dump(), one.record["effects"][0].dump());
  Profile renamed = all;
  renamed.name = "another";
  EXPECT_NE(test::degradeWith(renamed, gt, tree, 11).record["effects"][0].dump(), one.record["effects"][0].dump());
}

// The warp moves image, labels and graph together.
class Warp : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto ex = test::vascusynthExample(1000, 1);
    tree_ = new VascularTree(test::grow(ex));
    grid_ = mapGrid(100);
    clean_ = new GroundTruthVolumes(rasterizeGroundTruth(*tree_, grid_, RasterOptions{4}));
    // Control spacing 10 mm, displacements up to 3 mm (7.5 voxels): strongly curved vessels.
    const Profile p = profileFrom("w", "[[effect]]\ntype = \"warp\"\nspacing = \"10 mm\"\nmax_displacement = \"3 mm\"\n");
    warped_ = new DegradedImage(test::degradeWith(p, *clean_, *tree_, 5));
  }
  static void TearDownTestSuite() { delete warped_, delete clean_, delete tree_; }
  static inline VascularTree* tree_ = nullptr;
  static inline GroundTruthVolumes* clean_ = nullptr;
  static inline DegradedImage* warped_ = nullptr;
  static inline VolumeGrid grid_;
};

TEST_F(Warp, GraphCentrelinesLieInTheWarpedMaskAndOnTheWarpedVessels) {
  const auto& w = *warped_;
  ASSERT_TRUE(w.labels && w.tree);
  const auto& t = *w.tree;
  const auto& mask = w.labels->mask;
  const auto& fraction = w.labels->fraction;
  std::int64_t samples = 0, in_mask = 0, thick = 0, thick_on_vessel = 0;
  for (std::int32_t s = 1; s < t.nodeCount(); ++s) {
    const Vec3 a = t.position[t.parent[s]], b = t.position[s];
    const int n = std::max(1, static_cast<int>(std::ceil(t.length[s] / (0.25 * 0.4))));
    for (int q = 0; q <= n; ++q) {
      const Vec3 idx = grid_.index(a + (b - a) * (double(q) / n));
      const std::int64_t i = std::lround(idx.x), j = std::lround(idx.y), k = std::lround(idx.z);
      if (!grid_.contains(i, j, k)) continue;
      ++samples;
      in_mask += mask.at(i, j, k);
      // The warped image itself (not the centreline pass) shows thick vessels where the graph is.
      if (t.radius[s] >= 0.4) {
        ++thick;
        thick_on_vessel += sampleTrilinear(fraction, idx) >= 0.5f;
      }
    }
  }
  ASSERT_GT(samples, 10000);
  ASSERT_GT(thick, 1000);
  EXPECT_GE(double(in_mask) / samples, 0.99);
  EXPECT_GE(double(thick_on_vessel) / thick, 0.99) << thick_on_vessel << " of " << thick;
  std::printf("[ measure  ] graph samples in warped mask %.4f (%lld); thick-vessel samples on warped vessel %.4f (%lld)\n", double(in_mask) / samples,
              (long long)samples, double(thick_on_vessel) / thick, (long long)thick);
}

TEST_F(Warp, WarpedMaskAgreesWithTheMaskRasterizedFromTheWarpedTree) {
  const auto& w = *warped_;
  const auto re = rasterizeGroundTruth(*w.tree, grid_, RasterOptions{4});
  std::int64_t a = 0, b = 0, both = 0, moved = 0;
  for (std::size_t v = 0; v < re.mask.data.size(); ++v) {
    a += w.labels->mask.data[v];
    b += re.mask.data[v];
    both += w.labels->mask.data[v] & re.mask.data[v];
    moved += w.labels->mask.data[v] != clean_->mask.data[v];
  }
  const double dice = 2.0 * both / double(a + b);
  std::printf("[ measure  ] Dice(warped mask, mask of warped tree) = %.4f; %lld of %lld mask voxels moved\n", dice, (long long)moved, (long long)a);
  EXPECT_GE(dice, 0.95) << "Dice " << dice;
  // Not vacuous: most of the mask moved.
  EXPECT_GT(moved, a / 2);
}

TEST_F(Warp, IsInvertibleAndLabelsAreNeverInvented) {
  const auto& w = *warped_;
  EXPECT_GT(w.record["effects"][0]["min_jacobian_determinant"].get<double>(), 0.0);
  // φ and ψ are inverse: a tree point mapped forward and pulled back returns.
  Rng rng(5, 0, Stage::Degrade, 99);
  ASSERT_TRUE(w.warp);
  const BSplineWarp& warp = *w.warp;
  for (int i = 0; i < 200; ++i) {
    const Vec3 x = uniformPoint(rng, 0, 40);
    EXPECT_LT(distance(warp.pullback(warp.forward(x)), x), 1e-8);
  }
  // Labels are segment ids of the clean tree, on the mask only, and, where the warped image shows
  // a vessel, the clean label found where the pull-back lands.
  const std::int64_t nx = grid_.dims[0], ny = grid_.dims[1];
  std::int64_t unlabelled = 0, mask = 0, solid = 0, same = 0;
  for (std::int64_t v = 0; v < std::int64_t(w.labels->instances.data.size()); ++v) {
    const auto l = w.labels->instances.data[v];
    ASSERT_LT(l, std::uint32_t(tree_->nodeCount()));
    ASSERT_TRUE(l == 0 || w.labels->mask.data[v]);
    mask += w.labels->mask.data[v];
    unlabelled += w.labels->mask.data[v] && l == 0;
    if (w.labels->fraction.data[v] < 0.9f) continue;
    const Vec3 y = grid_.centre(v % nx, (v / nx) % ny, v / (nx * ny));
    const Vec3 idx = grid_.index(warp.pullback(y));
    ++solid;
    same += clean_->instances.at(std::lround(idx.x), std::lround(idx.y), std::lround(idx.z)) == l;
  }
  EXPECT_EQ(unlabelled, 0) << "of " << mask;
  EXPECT_GT(solid, 300);
  EXPECT_GE(double(same) / solid, 0.95) << same << " of " << solid;
  // The published description of the warp reproduces it: a B-spline of the listed displacements.
  const auto j = warp.describe();
  BSplineField fx(grid_, Vec3(j["spacing_mm"][0], j["spacing_mm"][1], j["spacing_mm"][2]));
  fx.coefficients() = j["displacement_x_mm"].get<std::vector<float>>();
  for (int i = 0; i < 50; ++i) {
    const Vec3 y = uniformPoint(rng, 0, 40);
    EXPECT_NEAR(fx.at(y), warp.displacement(y).x, 1e-9);
  }
  // Every piece of the warped graph knows its clean segment.
  ASSERT_EQ(w.segment_origin.size(), std::size_t(w.tree->nodeCount()));
  for (std::int32_t s = 1; s < w.tree->nodeCount(); ++s) ASSERT_GT(w.segment_origin[s], 0);
}

TEST(Degrade, DropoutsRemoveVesselContrastAtTheirGapsOnly) {
  const auto ex = test::vascusynthExample(1000, 2);
  const VascularTree tree = test::grow(ex);
  const VolumeGrid g = mapGrid(100);
  const auto gt = rasterizeGroundTruth(tree, g, RasterOptions{4});
  const auto d = test::degradeWith(profileFrom("d", "[[effect]]\ntype = \"dropout\"\ncount = 60\nlength = \"2 mm\"\n"), gt, tree);
  const auto& gaps = d.record["effects"][0]["gaps"];
  ASSERT_EQ(gaps.size(), 60u);
  // Depth 1: within the flat middle of every gap (±0.5 mm) all vessel signal is gone.
  int checked = 0;
  for (const auto& gap : gaps) {
    const Vec3 c(gap["centre_mm"][0], gap["centre_mm"][1], gap["centre_mm"][2]);
    bool had_vessel = false;
    for (std::int64_t k = 0; k < 100; ++k)
      for (std::int64_t j = 0; j < 100; ++j)
        for (std::int64_t i = 0; i < 100; ++i) {
          if (distance(g.centre(i, j, k), c) > 0.3) continue;
          EXPECT_LT(d.image.at(i, j, k), 1e-3f) << "gap on segment " << gap["segment"];
          had_vessel |= gt.fraction.at(i, j, k) >= 0.5f;
        }
    checked += had_vessel;
  }
  EXPECT_GT(checked, 10);
  // Far from every gap the image is the clean one.
  std::int64_t changed = 0;
  for (std::size_t v = 0; v < d.image.data.size(); ++v) changed += d.image.data[v] != 255.0f * gt.fraction.data[v];
  EXPECT_GT(changed, 0);
  EXPECT_LT(changed, std::int64_t(60 * 12 * 12 * 12));
}

TEST(Degrade, VascuSynthNoiseFilesReadAndMisspellingsAreNamed) {
  const auto ok = writeTemp("ok.txt", "GAUSSIAN: 0 20\r\n\r\nUNIFORM:-5 5\r\nSALTPEPPER: 255 0.05 0 0.05\r\nSHADOW: 3\r\n");
  const Profile p = readVascuSynthNoiseFile(ok);
  ASSERT_EQ(p.effects.size(), 4u);
  EXPECT_STREQ(p.effects[0].type->name, "gaussian");
  EXPECT_STREQ(p.effects[2].type->name, "impulse");
  EXPECT_EQ(p.effects[2].params.at("pepper_probability").components[0].lo.value, 0.05);
  EXPECT_STREQ(p.effects[3].type->name, "shadow");
  EXPECT_EQ(p.effects[3].line, 5);
  EXPECT_TRUE(p.clamp_each_step);
  const auto expectError = [](const std::string& name, const std::string& text, const std::string& want) {
    const auto f = writeTemp(name, text);
    try {
      readVascuSynthNoiseFile(f);
      return ::testing::AssertionFailure() << "no error for " << text;
    } catch (const InputError& e) {
      if (std::string(e.what()).rfind(f.string() + want, 0) == 0) return ::testing::AssertionSuccess();
      return ::testing::AssertionFailure() << e.what();
    }
  };
  EXPECT_TRUE(expectError("typo.txt", "GAUSSIAN: 0 20\nSALTPEPER 255 0.05 0 0.05\n", ":2: unknown noise directive 'SALTPEPER'"));
  EXPECT_TRUE(expectError("count.txt", "GAUSSIAN: 0\n", ":1: GAUSSIAN takes 2 values"));
  EXPECT_TRUE(expectError("nan.txt", "\nUNIFORM: a 5\n", ":2: UNIFORM low: 'a' is not a number"));
}

TEST(Degrade, ProfileErrorsNameFileAndLine) {
  const auto expectError = [](const std::string& text, const std::string& want) {
    const auto f = writeTemp("bad.toml", text);
    try {
      Profile p = readProfileToml(f);
      test::degradeWith(p, flatTruth(8), kNoTree);
      return ::testing::AssertionFailure() << "no error for " << text;
    } catch (const InputError& e) {
      if (std::string(e.what()).find(f.string() + want) == 0) return ::testing::AssertionSuccess();
      return ::testing::AssertionFailure() << e.what();
    }
  };
  EXPECT_TRUE(expectError("[[effect]]\ntype = \"gausian\"\n", ":2: unknown effect 'gausian'; allowed: gaussian,"));
  EXPECT_TRUE(expectError("[[effect]]\ntype = \"gaussian\"\nsigma = 2\nsigmaa = 3\n", ":4: unknown parameter 'sigmaa'"));
  EXPECT_TRUE(expectError("[[effect]]\ntype = \"gaussian\"\n", ":1: effect gaussian needs sigma"));
  EXPECT_TRUE(expectError("[[effect]]\ntype = \"blur\"\nsigma = \"1 furlong\"\n", ":3: unknown length unit"));
  EXPECT_TRUE(expectError("[[effect]]\ntype = \"gaussian\"\nsigma = -1\n", ":3: sigma = -1 is out of range"));
  EXPECT_TRUE(expectError("[[effect]]\ntype = \"gaussian\"\nsigma = {min = 3, max = 1}\n", ":3: the range of sigma has min > max"));
  EXPECT_TRUE(expectError("[[effect]]\ntype = \"warp\"\nspacing = \"4 voxel\"\nmax_displacement = \"2 voxel\"\n", ":1: warp: max_displacement"));
  EXPECT_TRUE(expectError("[[effect]]\ntype = \"warp\"\n[[effect]]\ntype = \"warp\"\n", ":3: a profile may hold one warp"));
}

TEST(Degrade, ShippedProfilesDrawWithinTheirRangesAndFitTheirDtype) {
  const auto ex = test::vascusynthExample(200, 4);
  const VascularTree tree = test::grow(ex);
  const VolumeGrid g = mapGrid(48);
  const auto gt = rasterizeGroundTruth(tree, g, RasterOptions{2});
  int profiles = 0;
  for (const auto& e : fs::directory_iterator(test::sourceDir() / "noise_profiles")) {
    const Profile p = readProfileToml(e.path());
    const auto d = test::degradeWith(p, gt, tree, 3);
    ++profiles;
    ASSERT_EQ(d.record["effects"].size(), p.effects.size()) << p.name;
    // Every drawn number lies within the profile's own range (plain amounts).
    for (std::size_t i = 0; i < p.effects.size(); ++i)
      for (const auto& [name, spec] : p.effects[i].params) {
        const auto& drawn = d.record["effects"][i]["parameters"][name];
        for (std::size_t c = 0; c < spec.components.size(); ++c) {
          const auto& r = spec.components[c];
          if (r.lo.ref != Amount::Ref::Plain || r.hi.ref != Amount::Ref::Plain) continue;
          const double v = drawn.is_array() ? drawn[c].get<double>() : drawn.get<double>();
          EXPECT_GE(v, r.lo.value - 1e-9) << p.name << " " << name;
          EXPECT_LE(v, r.hi.value + 1e-9) << p.name << " " << name;
        }
      }
    double lo, hi;
    dtypeRange(d.dtype, lo, hi);
    if (p.clamp_each_step) {
      for (float v : d.image.data) ASSERT_TRUE(v >= lo && v <= hi) << p.name;
    }
  }
  EXPECT_EQ(profiles, 7);
}

TEST(Degrade, TheDocsListEveryEffectAsTheCodeDeclaresIt) {
  std::ifstream in(test::sourceDir() / "docs/degradation.md");
  const std::string page((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(page.find(effectReference()), std::string::npos) << "run bash scripts/docs.sh: docs/degradation.md lists the effects";
}

TEST(Degrade, VascuSynthProfileAddsSigma20WhereTheImageIsNotClamped) {
  // Mid-grey everywhere: fraction ½ → 127.5, far from both clamps.
  auto gt = flatTruth(64);
  std::fill(gt.fraction.data.begin(), gt.fraction.data.end(), 0.5f);
  const auto d = test::degradeWith(readProfileToml(test::sourceDir() / "noise_profiles/vascusynth.toml"), gt, kNoTree);
  const auto m = moments(d.image.data);
  EXPECT_NEAR(m.mean, 127.5, 0.2);
  EXPECT_NEAR(m.sd, 20, 0.2);  // clamping at 0 and 255 (6σ away) changes nothing measurable
}

}  // namespace
}  // namespace angiosynth
