// Volumes rasterised chunk by chunk into OME-Zarr: the store read by zarr-python equals the
// in-memory volumes voxel for voxel, its pyramid and metadata are what OME-NGFF 0.4 readers
// expect, and tasks, resumed tasks and one process write the same bytes.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "cli_run.hpp"
#include "core/forest.hpp"
#include "raster/ground_truth.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace angiosynth;

namespace {

// Every file of a store but its records (.angiosynth), by path, with its bytes.
std::map<std::string, std::string> storeFiles(const fs::path& store) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(store)) {
    const std::string rel = fs::relative(e.path(), store).string();
    if (rel.rfind(".angiosynth", 0) == 0 || !e.is_regular_file()) continue;
    files[rel] = slurp(e.path());
  }
  return files;
}

// The A/V forest (two trees of two kinds, so the classes' crossing rule is exercised), small, with
// chunks of 32 voxels over a grid that is not a multiple of them.
fs::path avSample(const fs::path& dir, const std::string& formats) {
  std::string text = slurp(test::sourceDir() / "examples/cco_artery_vein_3d.toml");
  text.replace(text.find("terminals = 4000"), 16, "terminals = 600");
  text.replace(text.find("[image]\n"), 8, "[image]\nzarr_chunk = 32\n");
  std::ofstream(dir / "av.toml") << text;
  const ::Run r = run("generate av.toml --out av --quiet " + formats, dir);
  EXPECT_EQ(r.code, 0) << r.err;
  return dir / "av";
}

}  // namespace

TEST(ChunkedVolume, WindowsOfTheGridEqualTheWholeGrid) {
  // Windows of every size class (inside, at the far edges) with only the segments that reach
  // them, against the whole grid: every channel, every voxel.
  VascularTree t;
  t.addNode(Vec3(1.05, 1.3, 0.9), -1, 0);
  const auto a = t.addNode(Vec3(3.1, 1.7, 1.2), 0);
  const auto b = t.addNode(Vec3(4.6, 3.3, 2.9), a);
  const auto c = t.addNode(Vec3(4.9, 0.6, 0.4), a);
  t.radius[a] = 0.41, t.radius[b] = 0.23, t.radius[c] = 0.3;
  t.child0[0] = a, t.child0[a] = b, t.child1[a] = c;
  VolumeGrid g;
  g.dims = {53, 41, 37};
  g.spacing_mm = Vec3(0.1, 0.1, 0.1);
  g.origin_mm = Vec3(0.05, 0.05, 0.05);
  const RasterOptions opt{3, 26};
  Forest f;
  f.vessels = t;
  f.trees = {TreeInfo{"tree", "artery", 1}};
  const auto classes = segmentClasses(t, f.trees);
  GroundTruthVolumes whole = rasterizeGroundTruth(t, g, opt);
  fillClasses(whole, t, classes);
  std::int64_t compared = 0, inside = 0;
  for (const std::int64_t edge : {8, 16, 24}) {
    for (std::int64_t z0 = 0; z0 < g.dims[2]; z0 += edge)
      for (std::int64_t y0 = 0; y0 < g.dims[1]; y0 += edge)
        for (std::int64_t x0 = 0; x0 < g.dims[0]; x0 += edge) {
          const VoxelWindow w{{x0, y0, z0},
                              {std::min<std::int64_t>(x0 + edge, g.dims[0]), std::min<std::int64_t>(y0 + edge, g.dims[1]),
                               std::min<std::int64_t>(z0 + edge, g.dims[2])}};
          const std::vector<std::int32_t> segments{a, b, c};
          GroundTruthVolumes part = rasterizeGroundTruth(t, g, w, segments, opt);
          fillClasses(part, t, classes, g, w, segments);
          ASSERT_EQ(part.fraction.grid.dims[0], w.size(0));
          for (std::int64_t z = w.lo[2]; z < w.hi[2]; ++z)
            for (std::int64_t y = w.lo[1]; y < w.hi[1]; ++y)
              for (std::int64_t x = w.lo[0]; x < w.hi[0]; ++x) {
                const auto v = g.flat(x, y, z), u = w.flat(x, y, z);
                ASSERT_EQ(whole.fraction.data[v], part.fraction.data[u]) << x << " " << y << " " << z;
                ASSERT_EQ(whole.mask.data[v], part.mask.data[u]);
                ASSERT_EQ(whole.centerline.data[v], part.centerline.data[u]);
                ASSERT_EQ(whole.radius.data[v], part.radius.data[u]);
                ASSERT_EQ(whole.instances.data[v], part.instances.data[u]);
                ASSERT_EQ(whole.classes.data[v], part.classes.data[u]);
                ++compared;
                inside += whole.mask.data[v];
              }
        }
  }
  EXPECT_EQ(compared, 3 * g.voxelCount());
  EXPECT_GT(inside, 3 * 1000);  // the vessels are in the grid, not beside it
}

TEST(ChunkedVolume, ZarrPythonReadsTheInMemoryVolumesAndAnOmeNgffPyramid) {
  const fs::path dir = freshTestDir("angiosynth_zarr_");
  const fs::path sample = avSample(dir, "--format nifti --format zarr");
  // The same store from the sample's files, as a cluster would make it, with zlib.
  const ::Run r = run("rasterize av --out av_zlib.ome.zarr --compression zlib --quiet", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string out = debianPython(R"(
import json, numpy as np, nibabel as nib, zarr
bad = []
for store in ('av/volume.ome.zarr', 'av_zlib.ome.zarr'):
    root = zarr.open(store, mode='r')
    # Level 0: every channel equals the NIfTI the dense path wrote (x, y, z there; z, y, x here).
    for role, path in (('image', '0'), ('mask', 'labels/mask/0'), ('centerline', 'labels/centerline/0'), ('radius', 'radius/0'),
                       ('instances', 'labels/instances/0'), ('classes', 'labels/classes/0')):
        ref = np.asarray(nib.load('av/' + role + '.nii.gz').dataobj)
        got = np.transpose(root[path][...], (2, 1, 0))
        if ref.dtype != got.dtype or not np.array_equal(ref, got): bad.append((store, role, 'level 0'))
    # The pyramid, recomputed with NumPy from the level below (blocks at the far edges are partial).
    ms = root.attrs['multiscales'][0]
    n = len(ms['datasets'])
    for l in range(1, n):
        for path, how in (('fraction', 'mean'), ('radius', 'max'), ('labels/mask', 'max'), ('labels/centerline', 'max'),
                          ('labels/instances', 'mode'), ('labels/classes', 'mode')):
            lo = root[path + '/' + str(l - 1)][...]
            hi = root[path + '/' + str(l)][...]
            Z, Y, X = hi.shape
            pad = np.zeros((2 * Z, 2 * Y, 2 * X), lo.dtype)
            inside = np.zeros(pad.shape, bool)
            pad[:lo.shape[0], :lo.shape[1], :lo.shape[2]] = lo
            inside[:lo.shape[0], :lo.shape[1], :lo.shape[2]] = True
            cut = lambda a: a.reshape(Z, 2, Y, 2, X, 2).transpose(0, 2, 4, 1, 3, 5).reshape(Z, Y, X, 8)
            b, v = cut(pad), cut(inside)
            if how == 'mean':
                want = ((b.astype(np.float64) * v).sum(-1) / v.sum(-1)).astype(np.float32)
            elif how == 'max':
                want = b.max(-1)
            else:
                want = np.zeros(hi.shape, lo.dtype)
                for z, y, x in zip(*np.nonzero(b.max(-1))):
                    nz = b[z, y, x][b[z, y, x] > 0]
                    vals, counts = np.unique(nz, return_counts=True)
                    want[z, y, x] = vals[np.argmax(counts)]  # the lowest of the most frequent
            if not np.array_equal(want, hi): bad.append((store, path, l, int((want != hi).sum())))
        image = root[str(l)][...]
        frac = root['fraction/' + str(l)][...]
        if not np.array_equal(image, np.clip(np.round(frac.astype(np.float64) * 255), 0, 255).astype(np.uint8)): bad.append((store, 'image', l))
    # OME-NGFF 0.4: axes, one scale and one translation per level, voxel centres.
    if ms['version'] != '0.4' or [a['name'] for a in ms['axes']] != ['z', 'y', 'x']: bad.append((store, 'axes'))
    for l, d in enumerate(ms['datasets']):
        t = d['coordinateTransformations']
        s, o = t[0]['scale'], t[1]['translation']
        if t[0]['type'] != 'scale' or t[1]['type'] != 'translation' or d['path'] != str(l): bad.append((store, 'transform', l))
        if abs(s[0] - 0.3 * 2**l) > 1e-12 or abs(o[0] - (0.15 + (2**l - 1) / 2 * 0.3)) > 1e-12: bad.append((store, 'scale', l, s, o))
        if root[str(l)].shape != root['labels/mask/' + str(l)].shape: bad.append((store, 'shape', l))
    if root['labels'].attrs['labels'] != ['mask', 'centerline', 'instances', 'classes']: bad.append((store, 'labels'))
    if root['labels/mask'].attrs['image-label']['source']['image'] != '../../': bad.append((store, 'image-label'))
    if root['0'].chunks != (32, 32, 32): bad.append((store, 'chunks', root['0'].chunks))
print('codecs', zarr.open('av/volume.ome.zarr')['0'].compressor.codec_id, zarr.open('av_zlib.ome.zarr')['0'].compressor.codec_id)
print('levels', n, 'mask voxels', int(root['labels/mask/0'][...].sum()))
print('BAD', bad) if bad else print('ALL EQUAL')
)",
                                       dir);
  EXPECT_NE(out.find("ALL EQUAL"), std::string::npos) << out;
  EXPECT_NE(out.find("codecs blosc zlib"), std::string::npos) << out;
  EXPECT_NE(out.find("levels 4"), std::string::npos) << out;  // 100 voxels → 50, 25, 13: the last fits a chunk of 32
}

TEST(ChunkedVolume, TasksResumedTasksAndOneProcessWriteTheSameBytes) {
  const fs::path dir = freshTestDir("angiosynth_zarr_tasks_");
  avSample(dir, "--format png");
  ASSERT_EQ(run("rasterize av --out one.ome.zarr --quiet", dir).code, 0);
  for (int t = 0; t < 3; ++t) ASSERT_EQ(run("rasterize av --out split.ome.zarr --tasks 3 --task " + std::to_string(t) + " --quiet", dir).code, 0);
  // A task killed after its first batch: its record says so; the rerun resumes there.
  const fs::path progress = dir / "split.ome.zarr/.angiosynth/level0-task-1-of-3";
  const std::string finished = slurp(progress);
  std::ofstream(progress) << "2\n";
  const ::Run resumed = run("rasterize av --out split.ome.zarr --tasks 3 --task 1", dir);
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("2 done before"), std::string::npos) << resumed.err;
  EXPECT_EQ(slurp(progress), finished);
  // The pyramid waits for every task: task 2's record gone, it names task 2 and writes nothing.
  const fs::path last = dir / "split.ome.zarr/.angiosynth/level0-task-2-of-3";
  const std::string last_record = slurp(last);
  fs::remove(last);
  const ::Run early = run("rasterize av --out split.ome.zarr --tasks 3 --pyramid", dir);
  EXPECT_EQ(early.code, 2);
  EXPECT_NE(early.err.find("task(s) 2 of 3"), std::string::npos) << early.err;
  EXPECT_FALSE(fs::exists(dir / "split.ome.zarr/1/0"));
  std::ofstream(last) << last_record;
  ASSERT_EQ(run("rasterize av --out split.ome.zarr --tasks 3 --pyramid --quiet", dir).code, 0);
  const auto one = storeFiles(dir / "one.ome.zarr"), split = storeFiles(dir / "split.ome.zarr");
  EXPECT_GT(one.size(), 100u);
  EXPECT_TRUE(one == split) << one.size() << " files against " << split.size();
  // The sample's own store (made in one pass by generate) is the same too.
  const fs::path own = freshTestDir("angiosynth_zarr_own_");
  avSample(own, "--format zarr");
  EXPECT_TRUE(storeFiles(own / "av/volume.ome.zarr") == one);
}

TEST(ChunkedVolume, RefusesStoresThatAreNotItsJobAndBadSettings) {
  const fs::path dir = freshTestDir("angiosynth_zarr_refuse_");
  avSample(dir, "--format png");
  fs::create_directories(dir / "mine");
  std::ofstream(dir / "mine/notes.txt") << "my notes\n";
  ::Run r = run("rasterize av --out mine", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("holds no angiosynth store"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir / "mine/notes.txt"), "my notes\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir / "mine"), fs::directory_iterator()), 1);
  ASSERT_EQ(run("rasterize av --out store --quiet", dir).code, 0);
  r = run("rasterize av --out store --chunk 64", dir);  // another job in the same store
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("holds another rasterisation"), std::string::npos) << r.err;
  EXPECT_EQ(run("rasterize av --out other --chunk 12", dir).code, 2);  // not a multiple of 8
  EXPECT_FALSE(fs::exists(dir / "other"));
  EXPECT_EQ(run("rasterize av --out other --task 1", dir).code, 2);   // a task of how many?
  EXPECT_EQ(run("rasterize av/edges.csv --out other", dir).code, 2);  // a graph file needs a voxel size
  EXPECT_FALSE(fs::exists(dir / "other"));
  // A graph file with a voxel size: the grid covers its vessels.
  r = run("rasterize av/edges.csv --out graph.ome.zarr --voxel-size 0.5 --quiet", dir);
  EXPECT_EQ(r.code, 0) << r.err;
  std::string text = slurp(dir / "av.toml");
  text.replace(text.find("zarr_chunk = 32"), 15, "zarr_chunk = 12");
  std::ofstream(dir / "bad.toml") << text;
  r = run("generate bad.toml --out bad --format zarr", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.toml:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("multiple of 8"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "bad"));
}
