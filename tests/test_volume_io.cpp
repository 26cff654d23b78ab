// Volume and graph files as other tools read them: NIfTI through nibabel, GraphML through
// NetworkX, PNG/TIFF through OpenImageIO, MetaImage through VTK, NRRD by its header.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/graph_writers.hpp"
#include "io/volume_writers.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

using namespace angiosynth;
namespace fs = std::filesystem;

namespace {

std::string python(const std::string& script) { return debianPython(script, fs::temp_directory_path()); }

class VolumeFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = freshTestDir("angiosynth_vol_");
    grid_.dims = {7, 5, 3};
    grid_.spacing_mm = Vec3(0.5, 0.25, 2.0);
    grid_.origin_mm = Vec3(-3.0, 1.5, 10.0);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  VolumeGrid grid_;
};

TEST_F(VolumeFiles, NiftiReadByNibabelHasTheIntendedAffineAndExactLabels) {
  Volume<std::uint32_t> labels(grid_);
  for (std::size_t v = 0; v < labels.data.size(); ++v) labels.data[v] = static_cast<std::uint32_t>(v * 40503u + 7u);
  labels.at(6, 4, 2) = 4000000000u;
  Volume<float> image(grid_);
  for (std::size_t v = 0; v < image.data.size(); ++v) image.data[v] = 0.125f * float(v);
  writeNifti(dir_ / "labels.nii.gz", viewOf(labels, true, "labels"));
  writeNifti(dir_ / "image.nii.gz", viewOf(image, false, "image"));
  const std::string out = python(R"(
import nibabel as nib, numpy as np
d = ')" + dir_.string() + R"('
lab = nib.load(d + '/labels.nii.gz'); img = nib.load(d + '/image.nii.gz')
want = np.array([[0.5,0,0,-3.0],[0,0.25,0,1.5],[0,0,2.0,10.0],[0,0,0,1]])
print('affine', np.allclose(lab.affine, want, atol=1e-6), np.allclose(img.affine, want, atol=1e-6))
h = lab.header
print('codes', int(h['sform_code']), int(h['qform_code']), np.allclose(h.get_sform(), h.get_qform(), atol=1e-6))
print('units', h.get_xyzt_units()[0], 'intent', h.get_intent()[0])
a = np.asanyarray(lab.dataobj)
print('dtype', a.dtype, a.shape, int(a[6,4,2]), int(a[1,0,0]), int(a[0,1,0]), int(a[0,0,1]))
b = np.asanyarray(img.dataobj)
print('image', b.dtype, float(b[1,0,0]), float(b[0,1,0]), float(b[0,0,1]))
# ITK reads the same file in LPS: the centre of voxel (6,4,2) is RAS (0,2.5,14) -> LPS (-0,-2.5,14)
print('world', list(np.round(lab.affine @ [6,4,2,1], 6)[:3]))
)");
  EXPECT_NE(out.find("affine True True"), std::string::npos) << out;
  EXPECT_NE(out.find("codes 1 1 True"), std::string::npos) << out;
  EXPECT_NE(out.find("units mm intent label"), std::string::npos) << out;
  // x fastest: flat index v = i + 7 (j + 5 k).
  EXPECT_NE(out.find("dtype uint32 (7, 5, 3) 4000000000 40510 283528 1417612"), std::string::npos) << out;
  EXPECT_NE(out.find("image float32 0.125 0.875 4.375"), std::string::npos) << out;
  EXPECT_NE(out.find("world [0.0, 2.5, 14.0]"), std::string::npos) << out;
}

TEST_F(VolumeFiles, NrrdHeaderDescribesTheSameGeometryInLps) {
  Volume<std::uint8_t> m(grid_);
  writeNrrd(dir_ / "m.nrrd", viewOf(m, true, "mask"));
  std::ifstream in(dir_ / "m.nrrd", std::ios::binary);
  std::string header, line;
  while (std::getline(in, line) && !line.empty()) header += line + "\n";
  EXPECT_NE(header.find("space: left-posterior-superior"), std::string::npos) << header;
  EXPECT_NE(header.find("space directions: (-0.5,0,0) (0,-0.25,0) (0,0,2)"), std::string::npos) << header;
  EXPECT_NE(header.find("space origin: (3,-1.5,10)"), std::string::npos) << header;
  EXPECT_NE(header.find("sizes: 7 5 3"), std::string::npos) << header;
}

TEST_F(VolumeFiles, MetaImageReadByVtkHoldsTheNiftisVoxelsAndItsHeaderTheSameGeometryInLps) {
  Volume<std::uint32_t> labels(grid_);
  for (std::size_t v = 0; v < labels.data.size(); ++v) labels.data[v] = static_cast<std::uint32_t>(v * 40503u + 7u);
  Volume<float> image(grid_);
  for (std::size_t v = 0; v < image.data.size(); ++v) image.data[v] = 0.125f * float(v);
  for (const char* stem : {"labels", "image"}) {
    const bool label = std::string(stem) == "labels";
    const auto view = label ? viewOf(labels, true, stem) : viewOf(image, false, stem);
    writeNifti(dir_ / (std::string(stem) + ".nii.gz"), view);
    writeMetaImage(dir_ / (std::string(stem) + ".mha"), view);
  }
  // VTK's reader takes spacing, origin and voxels (not the direction, which the header states).
  const std::string out = python(R"(
import vtk, nibabel as nib, numpy as np
from vtk.util.numpy_support import vtk_to_numpy
d = ')" + dir_.string() + R"('
for stem in ('labels', 'image'):
    r = vtk.vtkMetaImageReader(); r.SetFileName(d + '/' + stem + '.mha'); r.Update()
    im = r.GetOutput(); dims = im.GetDimensions()
    a = vtk_to_numpy(im.GetPointData().GetScalars()).reshape(dims[::-1]).transpose(2, 1, 0)
    b = np.asanyarray(nib.load(d + '/' + stem + '.nii.gz').dataobj)
    print(stem, dims, im.GetSpacing(), im.GetOrigin(), a.dtype == b.dtype, np.array_equal(a, b))
)");
  EXPECT_NE(out.find("labels (7, 5, 3) (0.5, 0.25, 2.0) (3.0, -1.5, 10.0) True True"), std::string::npos) << out;
  EXPECT_NE(out.find("image (7, 5, 3) (0.5, 0.25, 2.0) (3.0, -1.5, 10.0) True True"), std::string::npos) << out;
  std::ifstream in(dir_ / "labels.mha", std::ios::binary);
  std::string header, line;
  while (std::getline(in, line) && line.rfind("ElementDataFile", 0) != 0) header += line + "\n";
  // RAS x and y negated: the direction's first two axes point to LPS -x and -y.
  EXPECT_NE(header.find("TransformMatrix = -1 0 0 0 -1 0 0 0 1\n"), std::string::npos) << header;
  EXPECT_NE(header.find("Offset = 3 -1.5 10\n"), std::string::npos) << header;
  EXPECT_NE(header.find("ElementType = MET_UINT\n"), std::string::npos) << header;
}

TEST(GraphFiles, GraphmlLoadsInNetworkxAndMatchesTheTree) {
  auto ex = test::vascusynthExample(50, 3);
  const VascularTree t = test::grow(ex);
  const fs::path file = fs::temp_directory_path() / ("angiosynth_tree_" + std::to_string(::getpid()) + ".graphml");
  std::ofstream(file) << [&] {
    std::ostringstream s;
    writeGraphml(s, t, singleTreeForest(VascularTree{}).trees);
    return s.str();
  }();
  const std::string out = python(R"(
import networkx as nx
g = nx.read_graphml(')" + file.string() +
                                 R"(')
print('graph', g.number_of_nodes(), g.number_of_edges(), nx.is_tree(g.to_undirected()))
print('root', g.nodes['n0']['type'], repr(g.edges['n0', list(g.successors('n0'))[0]]['radius']))
)");
  std::ostringstream want;
  want << "graph " << t.nodeCount() << " " << t.segmentCount() << " True";
  EXPECT_NE(out.find(want.str()), std::string::npos) << out;
  EXPECT_NE(out.find("root root " + std::to_string(t.radius[t.rootSegment()]).substr(0, 6)), std::string::npos) << out;
  fs::remove(file);
}

}  // namespace

#include <OpenImageIO/imageio.h>

namespace {

TEST_F(VolumeFiles, TiffHasOnePagePerSliceAndPngMipIsTheMaximum) {
  Volume<std::uint16_t> v(grid_);
  for (std::size_t i = 0; i < v.data.size(); ++i) v.data[i] = static_cast<std::uint16_t>(i * 97 % 60000);
  writeTiff(dir_ / "v.tif", viewOf(v, false, "test"));
  auto in = OIIO::ImageInput::open((dir_ / "v.tif").string());
  ASSERT_TRUE(in);
  int pages = 0;
  std::vector<std::uint16_t> page(std::size_t(grid_.dims[0]) * grid_.dims[1]);
  bool exact = true;
  while (in->seek_subimage(pages, 0)) {
    EXPECT_EQ(in->spec().width, 7);
    EXPECT_EQ(in->spec().height, 5);
    ASSERT_TRUE(in->read_image(pages, 0, 0, 1, OIIO::TypeDesc::UINT16, page.data()));
    for (std::size_t p = 0; p < page.size(); ++p) exact &= page[p] == v.data[pages * page.size() + p];
    ++pages;
  }
  EXPECT_EQ(pages, 3);
  EXPECT_TRUE(exact);

  Volume<float> f(grid_);
  f.at(2, 3, 1) = 1.0f;
  f.at(2, 3, 2) = 0.5f;
  f.at(6, 0, 0) = 0.25f;
  writePng(dir_ / "mip_z.png", maximumProjection(f, 2, 0.0, 1.0));
  auto png = OIIO::ImageInput::open((dir_ / "mip_z.png").string());
  ASSERT_TRUE(png);
  EXPECT_EQ(png->spec().width, 7);
  EXPECT_EQ(png->spec().height, 5);
  std::vector<std::uint8_t> px(35);
  ASSERT_TRUE(png->read_image(0, 0, 0, 1, OIIO::TypeDesc::UINT8, px.data()));
  EXPECT_EQ(px[2 + 7 * 3], 255);
  EXPECT_EQ(px[6], 64);
  EXPECT_EQ(px[0], 0);
}

}  // namespace
