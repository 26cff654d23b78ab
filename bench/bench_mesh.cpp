// Surface meshing (issue 15): the forest of each parameter file grown once, then its closed
// surface (src/mesh) at the automatic step (4 samples across the thinnest vessel) or --voxel MM:
//   bench_mesh FILE.toml ... [--voxel MM] [--threads T]
// Prints the step, the time, triangles in all and per segment, and the peak memory.
// Targets (issue 15): 10k segments ≤ 10 s, ≤ 4 GB, ≤ 500 triangles per segment; 100k ≤ 2 min.
#include <cstdio>

#include "bench_files.hpp"
#include "core/memory.hpp"
#include "mesh/vessel_surface.hpp"

using namespace angiosynth;

int main(int argc, char** argv) {
  std::vector<char*> rest;
  const double voxel = bench::takeOption(argc, argv, "--voxel", 0, rest);
  const auto args = bench::parseFileArgs(int(rest.size()), rest.data());
  std::printf("%-34s %9s %9s %10s %12s %10s %8s %9s\n", "file", "segments", "step mm", "mesh s", "triangles", "tri/seg", "genus0", "peak MiB");
  for (const auto& f : args.files) {
    const auto sc = readTomlParameters(f);
    const auto prepared = sc.growth->prepare(std::uint64_t(1) << 40);
    GrowthReport report;
    const Forest forest = prepared->grow(sc.seed.value_or(1), 0, report, {});
    const auto& t = forest.vessels;
    std::int64_t segments = 0;
    for (std::int32_t i = 0; i < t.nodeCount(); ++i) segments += !t.isRoot(i) && !t.isLink(i);
    SurfaceOptions o;
    o.voxel_mm = voxel;
    SurfaceReport rep;
    const auto t0 = std::chrono::steady_clock::now();
    const auto m = vesselSurface(t, o, &rep);
    const double s = bench::millisecondsSince(t0) / 1e3;
    const auto topo = meshTopology(m);
    int genus0 = 0;
    for (std::size_t k = 0; k < topo.tree_euler.size(); ++k) genus0 += topo.tree_components[k] == 1 && topo.tree_euler[k] == 2;
    std::printf("%-34s %9lld %9.4f %10.2f %12zu %10.0f %5d/%-2zu %9.0f\n", f.c_str(), (long long)segments, rep.voxel_mm, s, m.triangles.size(),
                double(m.triangles.size()) / double(segments), genus0, topo.tree_euler.size(), peakRssBytes() / 1048576.0);
  }
}
