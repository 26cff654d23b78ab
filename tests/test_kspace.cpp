// MR acquisition artefacts in k-space, each checked by the property that defines it, measured on
// the effect's output: Gibbs ringing's overshoot at a step edge, a spike's energy at its
// frequency (NumPy's FFT of the difference), motion ghosts at field of view ÷ period along the
// phase-encoding axis; and the labels of a sample with all three the same as without them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "cli_run.hpp"
#include "core/error.hpp"
#include "degrade_support.hpp"
#include "test_support.hpp"

namespace angiosynth {
namespace {

namespace fs = std::filesystem;

using test::flatTruth;
using test::profileFrom;

using test::degradeWith;

// A step from 0 to 100 along x (a square wave, k-space being periodic), k-space kept to its
// central eighth (|f| <= 64 of 1024): the overshoot beside each edge is 8.8227 % of the step, the
// value NumPy's FFT gives for the same truncation (Gibbs's limit for a continuous step is
// 8.95 %), and the plateaus far from the edges keep their level.
TEST(KSpace, GibbsRingingOvershootsAStepByNinePercent) {
  auto gt = flatTruth({1024, 1, 1});
  for (int x = 256; x < 768; ++x) gt.fraction.at(x, 0, 0) = 1;
  const auto d = degradeWith(profileFrom("gibbs", "background = 0\nvessel = 100\n[[effect]]\ntype = \"gibbs\"\nkeep_x = 0.125\n"), gt);
  const auto& v = d.image.data;
  const float peak = *std::max_element(v.begin(), v.end()), trough = *std::min_element(v.begin(), v.end());
  EXPECT_NEAR(peak - 100, 8.95, 0.25);  // the overshoot, % of the step
  EXPECT_NEAR(-trough, 8.95, 0.25);     // and the undershoot outside
  EXPECT_NEAR(v[512], 100, 1.0);        // mid-plateau
  EXPECT_NEAR(v[0], 0, 1.0);
  // Untruncated (keep 1), the step comes back exactly.
  const auto same = degradeWith(profileFrom("gibbs1", "background = 0\nvessel = 100\n[[effect]]\ntype = \"gibbs\"\n"), gt);
  for (int x = 0; x < 1024; ++x) ASSERT_NEAR(same.image.data[x], x >= 256 && x < 768 ? 100 : 0, 1e-3) << x;
}

// A spike at (5, -3, 2) cycles per field of view: the image's change is one plane wave, all of
// its energy at ±(5, -3, 2) in NumPy's FFT, of the height asked for.
TEST(KSpace, SpikePutsItsEnergyAtItsFrequency) {
  auto gt = flatTruth({32, 24, 16});
  for (int z = 4; z < 12; ++z)
    for (int y = 6; y < 18; ++y)
      for (int x = 10; x < 20; ++x) gt.fraction.at(x, y, z) = 1;
  const auto clean = degradeWith(profileFrom("none", "background = 20\nvessel = 120\n"), gt);
  const auto d = degradeWith(profileFrom("spike",
                                         "background = 20\nvessel = 120\n[[effect]]\ntype = \"kspace_spike\"\nkx = 5\nky = -3\nkz = 2\n"
                                         "amplitude = 0.05\n"),
                             gt);
  const fs::path dir = freshTestDir("angiosynth_kspace_spike_");
  {
    std::ofstream f(dir / "diff.f32", std::ios::binary);
    for (std::size_t v = 0; v < d.image.data.size(); ++v) {
      const float x = d.image.data[v] - clean.image.data[v];
      f.write(reinterpret_cast<const char*>(&x), sizeof x);
    }
  }
  const std::string out = debianPython(R"(
import numpy as np
d = np.fromfile('diff.f32', np.float32).reshape(16, 24, 32).transpose(2, 1, 0).astype(np.float64)
F = np.fft.fftn(d)
e = np.abs(F) ** 2
at = e[5, -3, 2] + e[-5, 3, -2]
print('share', at / e.sum(), 'peak', abs(F[5, -3, 2]))
)",
                                       dir);
  double share = 0, peak = 0;
  ASSERT_EQ(std::sscanf(out.c_str(), "share %lf peak %lf", &share, &peak), 2) << out;
  EXPECT_GT(share, 1 - 1e-9) << out;
  // Its height: 0.05 × k-space's centre, the sum of the clean image's voxels.
  double sum = 0;
  for (float x : clean.image.data) sum += x;
  EXPECT_NEAR(peak, 0.05 * sum, 1e-6 * sum) << out;
  fs::remove_all(dir);
  // A frequency the grid cannot hold is the profile's error, naming what it can.
  try {
    degradeWith(profileFrom("far", "[[effect]]\ntype = \"kspace_spike\"\nkx = 17\namplitude = 0.05\n"), gt);
    ADD_FAILURE() << "kx = 17 on 32 voxels was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("far.toml:1: k-space spike: kx = 17 lies beyond the grid's highest frequency; allowed: -16 to 16"),
              std::string::npos)
        << e.what();
  }
}

// One bright voxel on an empty image, lines along y modulated with a period of 8 of its 64
// lines: copies of a quarter of its brightness (amplitude 0.5 ÷ 2) 64 ÷ 8 = 8 voxels away along
// y on both sides, nothing along x or z.
TEST(KSpace, MotionGhostsSitAtTheFieldOfViewOverThePeriodAlongThePhaseAxis) {
  auto gt = flatTruth({32, 64, 16});
  gt.fraction.at(10, 20, 5) = 1;
  const auto d = degradeWith(profileFrom("ghost",
                                         "background = 0\nvessel = 1000\n[[effect]]\ntype = \"motion_ghost\"\naxis = 1\nperiod = 8\n"
                                         "amplitude = 0.5\n"),
                             gt);
  const auto& img = d.image;
  EXPECT_NEAR(img.at(10, 20, 5), 1000, 1e-2);
  EXPECT_NEAR(img.at(10, 28, 5), 250, 1e-2);
  EXPECT_NEAR(img.at(10, 12, 5), 250, 1e-2);
  double elsewhere = 0;
  for (std::int64_t k = 0; k < 16; ++k)
    for (std::int64_t j = 0; j < 64; ++j)
      for (std::int64_t i = 0; i < 32; ++i)
        if (!(i == 10 && k == 5 && (j == 20 || j == 28 || j == 12))) elsewhere = std::max<double>(elsewhere, img.at(i, j, k));
  EXPECT_LT(elsewhere, 1e-2);
}

// One bright voxel, one line in 4 along y kept: 4 copies of a quarter of its brightness, 64 ÷ 4
// = 16 voxels apart (the fold of an accelerated acquisition); with 16 centre lines kept in full
// the voxel keeps more than a quarter and its copies less.
TEST(KSpace, UndersamplingFoldsTheImageIntoFactorCopies) {
  auto gt = flatTruth({16, 64, 8});
  gt.fraction.at(5, 9, 3) = 1;
  const auto d = degradeWith(profileFrom("fold", "background = 0\nvessel = 1000\n[[effect]]\ntype = \"undersample\"\nfactor = 4\n"), gt);
  for (int m = 0; m < 4; ++m) EXPECT_NEAR(d.image.at(5, (9 + 16 * m) % 64, 3), 250, 1e-2) << m;
  double total = 0;
  for (float x : d.image.data) total += x;
  EXPECT_NEAR(total, 1000, 1e-1);  // nothing but the four copies
  EXPECT_NEAR(d.record["effects"][0]["lines_acquired_share"].get<double>(), 0.25, 1e-12) << d.record.dump();
  const auto acs =
      degradeWith(profileFrom("acs", "background = 0\nvessel = 1000\n[[effect]]\ntype = \"undersample\"\nfactor = 4\ncentre_lines = 16\n"), gt);
  EXPECT_GT(acs.image.at(5, 9, 3), 300);
  EXPECT_LT(acs.image.at(5, 25, 3), 250);
}

// The three effects in one profile through `generate`: the sample's mask, centreline and classes
// are the bytes of the same sample without the profile (intensity-only effects move no label),
// and the degraded image the same on one thread as on two.
TEST(KSpace, LabelsAreTheCleanRunsBytes) {
  const fs::path dir = freshTestDir("angiosynth_kspace_labels_");
  std::ofstream(dir / "mr.toml") << "description = \"k-space artefacts\"\nbackground = 100\nvessel = 400\n"
                                    "[[effect]]\ntype = \"gibbs\"\nkeep_x = 0.6\nkeep_y = 0.5\n"
                                    "[[effect]]\ntype = \"kspace_spike\"\nkx = {min = -10, max = 10}\nky = 4\namplitude = 0.02\n"
                                    "[[effect]]\ntype = \"motion_ghost\"\nperiod = {min = 4, max = 12}\namplitude = 0.2\n";
  std::ofstream(dir / "p.toml") << test::kSmallCcoSample;
  ASSERT_EQ(run("generate p.toml --out plain --no-profiles --quiet", dir).code, 0);
  const auto r = run("generate p.toml --out mr --profile mr.toml --quiet", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"mask.nii.gz", "centerline.nii.gz", "radius.nii.gz", "classes.nii.gz"})
    if (fs::exists(dir / "plain" / f)) { EXPECT_EQ(slurp(dir / "plain" / f), slurp(dir / "mr" / f)) << f; }
  // The same bytes whatever the threads (FFTW plans without regard to timing or alignment).
  ASSERT_EQ(run("generate p.toml --out mr1 --profile mr.toml --threads 1 --quiet", dir).code, 0);
  EXPECT_EQ(slurp(dir / "mr/image_mr.nii.gz"), slurp(dir / "mr1/image_mr.nii.gz"));
  EXPECT_NE(slurp(dir / "mr/image_mr.nii.gz"), slurp(dir / "plain/image.nii.gz"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace angiosynth
