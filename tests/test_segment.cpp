// The reference segmenters: vesselness that prefers tubes to plates and blobs, dark vessels as
// bright ones inverted, Otsu's threshold and the Frangi and Sato responses against scikit-image's
// on a shipped example's image, and the mask written on the image's grid (score accepts it).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "cli_run.hpp"
#include "segment/segment.hpp"
#include "test_support.hpp"

namespace angiosynth {
namespace {

namespace fs = std::filesystem;

Volume<float> emptyImage(int n) {
  VolumeGrid g;
  g.dims = {n, n, n};
  g.spacing_mm = Vec3(1, 1, 1);
  return Volume<float>(g);
}

// A bright tube (radius 2 along x), a plate (4 thick, normal z) and a ball (radius 4), apart:
// Frangi's response on the tube's axis is near its maximum, on the plate's centre under a tenth
// of it and on the ball's under a fifth, and nothing far from all three.
TEST(Segment, VesselnessPrefersTubesToPlatesAndBlobs) {
  Volume<float> img = emptyImage(64);
  for (std::int64_t k = 0; k < 64; ++k)
    for (std::int64_t j = 0; j < 64; ++j)
      for (std::int64_t i = 0; i < 64; ++i) {
        const double tube = std::hypot(j - 16.0, k - 16.0),
                     ball = std::sqrt((i - 44.0) * (i - 44.0) + (j - 44.0) * (j - 44.0) + (k - 44.0) * (k - 44.0));
        float& v = img.at(i, j, k);
        if (tube <= 2) v = 100;
        if (j >= 34 && j < 60 && i < 24 && k >= 42 && k < 46) v = 100;  // the plate
        if (ball <= 4) v = 100;
      }
  SegmentOptions o;
  o.sigmas_mm = {1, 2, 3};
  o.gamma = 0;  // half the largest Hessian norm: the response independent of the intensity scale
  SegmentSummary s;
  Volume<float> response;
  segment(img, o, s, &response);
  const float tube = response.at(32, 16, 16), plate = response.at(12, 47, 44), ball = response.at(44, 44, 44), far = response.at(50, 10, 50);
  EXPECT_GT(tube, 0.5 * s.max_response);
  EXPECT_LT(plate, 0.1 * tube);
  EXPECT_LT(ball, 0.2 * tube);
  EXPECT_EQ(far, 0);
  // Jerman's measure reads λ2 and λ3 only: full on the tube, nothing on the plate (λ2 ≈ 0); a
  // ball, all three large, responds too (Jerman et al. leave blobs to the scale selection).
  o.method = "jerman";
  segment(img, o, s, &response);
  EXPECT_NEAR(response.at(32, 16, 16), 1, 1e-6);
  EXPECT_LT(response.at(12, 47, 44), 0.1);
}

// Dark vessels: the negated image with --dark gives the bright image's mask, bit for bit.
TEST(Segment, DarkVesselsAreBrightVesselsInverted) {
  Volume<float> img = emptyImage(32);
  for (std::int64_t i = 0; i < 32; ++i) img.at(i, 16, 16) = img.at(i, 16, 17) = 50;
  Volume<float> neg = img;
  for (float& v : neg.data) v = -v;
  for (const char* method : {"frangi", "sato", "jerman", "otsu"}) {
    SegmentOptions o;
    o.method = method;
    SegmentSummary s1, s2;
    const auto bright = segment(img, o, s1);
    o.bright = false;
    const auto dark = segment(neg, o, s2);
    EXPECT_EQ(bright.data, dark.data) << method;
    EXPECT_GT(s1.voxels, 0) << method;
  }
}

// Otsu's threshold between two groups of values (10-16 and 200-204): every split between them
// separates the groups alike, and the first wins, the centre of the 256-bin histogram's bin
// holding 16 (lo + 7.5 × (204 − 10) / 256), as scikit-image's threshold_otsu returns it.
TEST(Segment, OtsuSplitsTwoGroups) {
  std::vector<float> v;
  for (int i = 0; i < 900; ++i) v.push_back(10 + (i % 7));
  for (int i = 0; i < 100; ++i) v.push_back(200 + (i % 5));
  EXPECT_NEAR(otsuThreshold(v.data(), v.size()), 10 + 7.5 * 194.0 / 256, 1e-9);
  EXPECT_THROW(
      {
        SegmentOptions o;
        o.method = "watershed";
        SegmentSummary s;
        segment(emptyImage(4), o, s);
      },
      std::invalid_argument);
}

// On the VascuSynth-like example's CTA image (100³, 0.4 mm): the Frangi and Sato responses of
// `segment` against scikit-image's frangi and sato with the same scales, constants and borders
// (float image, bright ridges, the border voxel repeated: mode "nearest"): Pearson correlation
// ≥ 0.9999 (the same arithmetic in single precision; with scikit-image's default "reflect"
// borders 0.980 and 0.989, the interior alike); Otsu's mask as scikit-image's threshold_otsu
// gives it; the mask on the image's grid, as score's grid check and nibabel see it; and score's
// false positives on the distractor label as NumPy counts them.
TEST(Segment, ResponsesAgreeWithScikitImageOnAShippedExample) {
  const fs::path dir = freshTestDir("angiosynth_segment_");
  const fs::path src = test::sourceDir();
  ASSERT_EQ(run("generate '" + (src / "examples/vascusynth_like.toml").string() + "' --out s --profile cta --format nifti --quiet", dir).code, 0);
  for (const char* method : {"frangi", "sato", "otsu"}) {
    const auto r = run(std::string("segment s/image_cta.nii.gz --method ") + method + " --sigmas 0.4,0.8,1.2 --out " + method +
                           ".nii.gz --response " + method + "_response.nii.gz",
                       dir);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  const std::string out = debianPython(R"(
import nibabel as nib, numpy as np
from skimage.filters import frangi, sato, threshold_otsu
img = nib.load('s/image_cta.nii.gz')
a = np.asanyarray(img.dataobj).astype(np.float32)
for name, ref in [('frangi', frangi(a, sigmas=[1, 2, 3], alpha=0.5, beta=0.5, gamma=15, black_ridges=False, mode='nearest')),
                  ('sato', sato(a, sigmas=[1, 2, 3], black_ridges=False, mode='nearest'))]:
    ours = np.asanyarray(nib.load(name + '_response.nii.gz').dataobj)
    print(name, 'correlation', np.corrcoef(ours.ravel(), ref.ravel())[0, 1])
t = threshold_otsu(a)
ours = nib.load('otsu_response.nii.gz')
mask = nib.load('otsu.nii.gz')
print('otsu agree', np.mean((np.asanyarray(mask.dataobj) > 0) == (a > t)))
print('same grid', np.allclose(mask.affine, img.affine, atol=1e-5))
)",
                                       dir);
  for (const char* method : {"frangi", "sato"}) {
    const auto at = out.find(std::string(method) + " correlation ");
    ASSERT_NE(at, std::string::npos) << out;
    EXPECT_GE(std::stod(out.substr(at + std::strlen(method) + 13)), 0.9999) << out;
  }
  const auto agree = out.find("otsu agree ");
  ASSERT_NE(agree, std::string::npos) << out;
  EXPECT_GT(std::stod(out.substr(agree + 11)), 0.999) << out;
  EXPECT_NE(out.find("same grid True"), std::string::npos) << out;
  // score reads it on the sample's grid, and counts its false positives on the CTA image's bone
  // and plaque (the distractor label) as NumPy does.
  const auto scored = run("score otsu.nii.gz s --out scores.json", dir);
  ASSERT_EQ(scored.code, 0) << scored.err;
  const std::string counted = debianPython(R"(
import json, nibabel as nib, numpy as np
p = np.asanyarray(nib.load('otsu.nii.gz').dataobj) > 0
t = np.asanyarray(nib.load('s/mask.nii.gz').dataobj) > 0
d = np.asanyarray(nib.load('s/distractors_cta.nii.gz').dataobj)
block = json.load(open('scores.json'))['distractors']
on = (d > 0) & ~t
print('share', abs(block['share_called_vessel'] - (p & on).sum() / on.sum()) < 1e-12)
print('of false positives', abs(block['share_of_false_positives'] - (p & on).sum() / (p & ~t).sum()) < 1e-12)
)",
                                           dir);
  EXPECT_NE(counted.find("share True"), std::string::npos) << counted;
  EXPECT_NE(counted.find("of false positives True"), std::string::npos) << counted;
  // A bad method is refused before anything is written.
  const auto bad = run("segment s/image_cta.nii.gz --method watershed --out bad.nii.gz", dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("allowed: otsu, frangi, sato, jerman"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad.nii.gz"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace angiosynth
