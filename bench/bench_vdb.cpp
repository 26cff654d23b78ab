// The sparse path at scale: a 10k-terminal tree into 2048³ (40 mm field of view, 19.5 µm voxels)
// at S = 4, written as OpenVDB; prints time and peak memory (target: under 8 GB).
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "bench_common.hpp"
#include "core/memory.hpp"
#include "grow/vascusynth/grower.hpp"
#include "io/vdb_writer.hpp"

using namespace angiosynth;

int main(int argc, char** argv) {
  const int size = argc > 1 ? std::atoi(argv[1]) : 2048;
  const DemandMap m = bench::vascusynthMap(100, false);
  GrowthReport r;
  const VascularTree tree = growVascuSynth(m, bench::vascusynthOptions(m, 10000), r);
  const auto grown_rss = peakRssBytes();
  VolumeGrid g;
  g.dims = {size, size, size};
  const double h = 40.0 / size;
  g.spacing_mm = Vec3(h, h, h);
  g.origin_mm = Vec3(h / 2, h / 2, h / 2);
  const auto t0 = std::chrono::steady_clock::now();
  const BrickBins bins = binSegments(tree, g);
  const auto path = std::filesystem::temp_directory_path() / "angiosynth_bench.vdb";
  const VdbReport rep = writeVdb(path, tree, g, bins, RasterOptions{4});
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%d^3 (%.3g voxels): %.1f s, %lld leaves, %lld active voxels, file %.1f MiB, estimate %s, peak RSS %s (after growth %s)\n", size,
              double(g.voxelCount()), s, (long long)rep.leaves, (long long)rep.active_voxels, double(std::filesystem::file_size(path)) / (1 << 20),
              formatBytes(sparseRasterBytes(bins)).c_str(), formatBytes(peakRssBytes()).c_str(), formatBytes(grown_rss).c_str());
  std::filesystem::remove(path);
}
