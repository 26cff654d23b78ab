// Partial-volume accuracy and label connectivity of the rasterizer.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <numbers>
#include <queue>

#include "core/distributions.hpp"
#include "core/rng.hpp"
#include "raster/ground_truth.hpp"
#include "test_support.hpp"

using namespace angiosynth;

namespace {

VascularTree singleSegment(const Vec3& a, const Vec3& b, double r) {
  VascularTree t;
  t.addNode(a, -1);
  t.addNode(b, 0);
  t.radius[1] = r;
  return t;
}

VolumeGrid cubeGrid(int n, double spacing) {
  VolumeGrid g;
  g.dims = {n, n, n};
  g.spacing_mm = Vec3(spacing, spacing, spacing);
  g.origin_mm = Vec3(0, 0, 0);
  return g;
}

TEST(Raster, CapsulesAtRandomOrientationsMatchTheirAnalyticVolume) {
  Rng rng(11, 0, Stage::Raster);
  const double h = 0.5;  // mm per voxel
  for (double r_vox : {0.5, 0.8, 1.0, 2.0, 3.5, 5.0, 7.5, 10.0}) {
    for (int trial = 0; trial < 3; ++trial) {
      const double r = r_vox * h, len = (20 + 30 * rng.uniform()) * h;
      // A random direction, uniform on the sphere.
      const double z = rng.uniform(-1, 1), phi = rng.uniform(0, 2 * std::numbers::pi);
      const Vec3 dir(std::sqrt(1 - z * z) * std::cos(phi), std::sqrt(1 - z * z) * std::sin(phi), z);
      const int n = static_cast<int>(std::ceil((len + 2 * r) / h)) + 6;
      const VolumeGrid g = cubeGrid(n, h);
      const Vec3 centre = g.centre(n / 2, n / 2, n / 2) + uniformPoint(rng, -0.5, 0.5) * h;
      const VascularTree t = singleSegment(centre - dir * (len / 2), centre + dir * (len / 2), r);
      Volume<float> f;
      Volume<std::uint32_t> id;
      rasterizeDense(t, g, RasterOptions{4}, f, id);
      double sum = 0;
      for (float v : f.data) sum += v;
      const double measured = sum * h * h * h;
      const double exact = std::numbers::pi * r * r * len + 4.0 / 3.0 * std::numbers::pi * r * r * r;
      EXPECT_NEAR(measured, exact, 0.01 * exact) << "radius " << r_vox << " voxels";
    }
  }
}

TEST(Raster, WhollyInsideIsOneWhollyOutsideIsZero) {
  const VolumeGrid g = cubeGrid(40, 1.0);
  const VascularTree t = singleSegment(Vec3(5, 20, 20), Vec3(35, 20, 20), 6.0);
  Volume<float> f;
  Volume<std::uint32_t> id;
  rasterizeDense(t, g, RasterOptions{4}, f, id);
  const double half_diag = std::sqrt(3.0) / 2;
  for (int k = 0; k < 40; ++k)
    for (int j = 0; j < 40; ++j)
      for (int i = 0; i < 40; ++i) {
        const double d = pointSegmentDistance(g.centre(i, j, k), Vec3(5, 20, 20), Vec3(35, 20, 20));
        if (d < 6.0 - half_diag) { EXPECT_EQ(f.at(i, j, k), 1.0f); }
        if (d > 6.0 + half_diag) { EXPECT_EQ(f.at(i, j, k), 0.0f); }
        if (f.at(i, j, k) > 0) { EXPECT_EQ(id.at(i, j, k), 1u); }
      }
}

class GrownRaster : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ex_ = new test::Example(test::vascusynthExample(1000, 1));
    tree_ = new VascularTree(test::grow(*ex_));
  }
  static void TearDownTestSuite() {
    delete tree_;
    delete ex_;
  }
  static VolumeGrid mapGrid() {
    VolumeGrid g;
    g.dims = ex_->map.dims;
    g.spacing_mm = Vec3(1, 1, 1) * ex_->map.voxel_mm;
    g.origin_mm = g.spacing_mm * 0.5;  // voxel centres of the demand map
    return g;
  }
  static test::Example* ex_;
  static VascularTree* tree_;
};
test::Example* GrownRaster::ex_ = nullptr;
VascularTree* GrownRaster::tree_ = nullptr;

TEST_F(GrownRaster, CentrelinesLieInTheMaskAndTheMaskIsOneComponent) {
  const VolumeGrid g = mapGrid();
  const auto gt = rasterizeGroundTruth(*tree_, g, RasterOptions{4});
  const auto& t = *tree_;
  // Every centreline sample of every segment is in the mask, with that segment's radius region.
  for (std::int32_t s = 1; s < t.nodeCount(); ++s)
    for (int q = 0; q <= 32; ++q) {
      const Vec3 p = t.position[t.parent[s]] + (t.position[s] - t.position[t.parent[s]]) * (q / 32.0);
      const Vec3 c = g.index(p);
      const auto i = std::int64_t(std::floor(c.x + 0.5)), j = std::int64_t(std::floor(c.y + 0.5)), k = std::int64_t(std::floor(c.z + 0.5));
      ASSERT_TRUE(g.contains(i, j, k));
      EXPECT_EQ(gt.mask.at(i, j, k), 1) << "segment " << s << " radius " << t.radius[s];
    }
  // One 26-connected component.
  std::vector<std::uint8_t> seen(gt.mask.data.size(), 0);
  std::int64_t total = 0, start = -1;
  for (std::size_t v = 0; v < gt.mask.data.size(); ++v)
    if (gt.mask.data[v]) ++total, start = start < 0 ? std::int64_t(v) : start;
  ASSERT_GT(total, 0);
  std::queue<std::int64_t> todo;
  todo.push(start);
  seen[start] = 1;
  std::int64_t reached = 0;
  const auto& d = g.dims;
  while (!todo.empty()) {
    const auto v = todo.front();
    todo.pop();
    ++reached;
    const std::int64_t i = v % d[0], j = (v / d[0]) % d[1], k = v / (std::int64_t(d[0]) * d[1]);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (!g.contains(i + dx, j + dy, k + dz)) continue;
          const auto w = g.flat(i + dx, j + dy, k + dz);
          if (gt.mask.data[w] && !seen[w]) seen[w] = 1, todo.push(w);
        }
  }
  EXPECT_EQ(reached, total);
  // Labels agree: instances only on the mask, radius only on the centreline.
  for (std::size_t v = 0; v < gt.mask.data.size(); ++v) {
    if (!gt.mask.data[v]) { EXPECT_EQ(gt.instances.data[v], 0u); }
    if (gt.mask.data[v]) { EXPECT_NE(gt.instances.data[v], 0u); }
    EXPECT_EQ(gt.radius.data[v] > 0, gt.centerline.data[v] == 1);
  }
}

TEST_F(GrownRaster, IdenticalWhateverTheThreads) {
  const VolumeGrid g = mapGrid();
  const auto a = rasterizeGroundTruth(*tree_, g, RasterOptions{4});
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const auto b = rasterizeGroundTruth(*tree_, g, RasterOptions{4});
  EXPECT_EQ(a.fraction.data, b.fraction.data);
  EXPECT_EQ(a.instances.data, b.instances.data);
  EXPECT_EQ(a.mask.data, b.mask.data);
}

TEST(Raster, CentrelineCurveIs26ConnectedAndHitsBothEnds) {
  const VolumeGrid g = cubeGrid(50, 1.0);
  std::vector<std::array<std::int64_t, 3>> c;
  centerlineVoxels(g, Vec3(3.2, 40.7, 10.1), Vec3(45.6, 2.2, 33.9), c);
  ASSERT_FALSE(c.empty());
  EXPECT_EQ(c.front(), (std::array<std::int64_t, 3>{3, 41, 10}));
  EXPECT_EQ(c.back(), (std::array<std::int64_t, 3>{46, 2, 34}));
  for (std::size_t n = 1; n < c.size(); ++n)
    for (int ax = 0; ax < 3; ++ax) EXPECT_LE(std::llabs(c[n][ax] - c[n - 1][ax]), 1);
}

}  // namespace
