// The sparse OpenVDB path agrees voxel for voxel with the dense rasterizer.
#include <gtest/gtest.h>
#include <unistd.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <filesystem>

#include "io/vdb_writer.hpp"
#include "raster/ground_truth.hpp"
#include "test_support.hpp"

using namespace angiosynth;

TEST(Vdb, SparseGridsMatchTheDenseRasterAndCarryTheGeometry) {
  auto ex = test::vascusynthExample(300, 2);
  const VascularTree t = test::grow(ex);
  VolumeGrid g;
  g.dims = {90, 100, 110};  // not a multiple of the brick size
  g.spacing_mm = Vec3(0.45, 0.4, 0.37);
  g.origin_mm = Vec3(0.2, -0.3, 0.1);
  const auto dense = rasterizeGroundTruth(t, g, RasterOptions{3});
  const auto file = std::filesystem::temp_directory_path() / ("angiosynth_test_" + std::to_string(::getpid()) + ".vdb");
  const VdbReport rep = writeVdb(file, t, g, binSegments(t, g), RasterOptions{3});
  EXPECT_GT(rep.leaves, 0);

  openvdb::initialize();
  openvdb::io::File in(file.string());
  in.open();
  auto fgrid = openvdb::gridPtrCast<openvdb::FloatGrid>(in.readGrid("fraction"));
  auto igrid = openvdb::gridPtrCast<openvdb::Int32Grid>(in.readGrid("instances"));
  in.close();
  ASSERT_TRUE(fgrid && igrid);
  const auto world = fgrid->transform().indexToWorld(openvdb::Coord(4, 5, 6));
  EXPECT_NEAR(world.x(), 0.2 + 4 * 0.45, 1e-12);
  EXPECT_NEAR(world.y(), -0.3 + 5 * 0.4, 1e-12);
  EXPECT_NEAR(world.z(), 0.1 + 6 * 0.37, 1e-12);
  std::int64_t active = 0, mismatches = 0;
  auto fa = fgrid->getConstAccessor();
  auto ia = igrid->getConstAccessor();
  for (std::int32_t k = 0; k < g.dims[2]; ++k)
    for (std::int32_t j = 0; j < g.dims[1]; ++j)
      for (std::int32_t i = 0; i < g.dims[0]; ++i) {
        const openvdb::Coord c(i, j, k);
        const float f = fa.getValue(c);
        mismatches += f != dense.fraction.at(i, j, k);
        active += fa.isValueOn(c);
        // Instances agree wherever the mask comes from the partial volume.
        if (dense.fraction.at(i, j, k) >= 0.5f) mismatches += std::uint32_t(ia.getValue(c)) != dense.instances.at(i, j, k);
      }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(active, rep.active_voxels);
  std::int64_t dense_nonzero = 0;
  for (float f : dense.fraction.data) dense_nonzero += f > 0;
  EXPECT_EQ(active, dense_nonzero);
  std::filesystem::remove(file);
}
