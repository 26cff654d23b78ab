// L-system grammar mode: growth of each parameter file (best of 5, the final overlap
// count apart), then the tree rasterised with every channel into a 512 × 512 × 140 grid over its
// bounding box (V-System's voxelisation), best of 3:
//   bench_lsystem FILE.toml ... [--threads T] [--supersampling S]
// Targets: 14 generations (16,384 tips) ≤ 0.2 s; rasterising them ≤ 0.3 s.
#include <algorithm>
#include <cstdio>

#include "bench_files.hpp"
#include "core/memory.hpp"
#include "raster/ground_truth.hpp"

using namespace angiosynth;

int main(int argc, char** argv) {
  // --supersampling S (default 4, the image default; 1: one sample per voxel, a binary-like mask).
  std::vector<char*> rest;
  const int supersampling = int(bench::takeOption(argc, argv, "--supersampling", 4, rest));
  const auto args = bench::parseFileArgs(int(rest.size()), rest.data());
  std::printf("%-32s %9s %9s %9s %9s %10s %10s\n", "file", "grow ms", "check ms", "tips", "segments", "raster ms", "peak MiB");
  for (const auto& f : args.files) {
    const auto run = bench::bestOfFive(f);
    const VascularTree& t = run.forest.vessels;
    Vec3 lo = t.position[0], hi = lo;
    double rmax = 0;
    for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
      const Vec3& p = t.position[i];
      lo = componentMin(lo, p);
      hi = componentMax(hi, p);
      rmax = std::max(rmax, t.radius[i]);
    }
    VolumeGrid g;
    g.dims = {512, 512, 140};
    const Vec3 span = hi - lo + Vec3(2 * rmax, 2 * rmax, 2 * rmax);
    g.spacing_mm = Vec3(span.x / 512, span.y / 512, span.z / 140);
    g.origin_mm = lo - Vec3(rmax, rmax, rmax) + g.spacing_mm * 0.5;
    double raster = 1e300;
    for (int run = 0; run < 3; ++run) {
      const auto t0 = std::chrono::steady_clock::now();
      const auto gt = rasterizeGroundTruth(t, g, RasterOptions{supersampling, 26});
      raster = std::min(raster, bench::millisecondsSince(t0));
    }
    std::printf("%-32s %9.1f %9.1f %9lld %9d %10.1f %10.1f\n", f.c_str(), run.grow_ms, run.check_ms, (long long)run.stats.value("tips", 0),
                t.segmentCount(), raster, peakRssBytes() / 1048576.0);
  }
}
