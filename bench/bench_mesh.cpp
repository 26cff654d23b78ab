// Surface meshing: the forest of each parameter file grown once, then its closed
// surface (src/mesh): tubes joined to contoured junctions (--tubes 1, the default; --samples N
// across each vessel where vessels meet, default 3) or contoured whole (--tubes 0; 4 samples
// across), optionally decimated (--decimate 1) or with the contour's slivers repaired
// (--slivers DEG: angles below DEG or edges under 0.35 of the step; 0, the default for closed ends, none; with
// --max-angle DEG, angles above DEG improved: 90 is the default with capped ends), the tubes' rings at
// most --ring-spacing R radii apart (default 8; 0: capped ends' 1.5 vertex spacings, staggered), the contoured
// parts remeshed isotropically (--remesh 1, the default with capped ends), at the automatic step or --voxel MM:
//   bench_mesh FILE.toml ... [--tubes 0|1] [--samples N] [--decimate 0|1] [--slivers DEG] [--max-angle DEG] [--nets 0|1] [--ring-spacing R]
//              [--remesh 0|1] [--voxel MM] [--threads T]
// Prints the step, the time, triangles in all and per segment, and the peak memory.
// Targets: 10k segments ≤ 10 s, ≤ 4 GB, ≤ 500 triangles per segment; 100k ≤ 2 min.
#include <cstdio>

#include "bench_files.hpp"
#include "core/memory.hpp"
#include <cstdlib>
#include <fstream>

#include "io/mesh_writers.hpp"
#include "mesh/tube_surface.hpp"
#include "mesh/vessel_surface.hpp"

using namespace angiosynth;

int main(int argc, char** argv) {
  std::vector<char*> rest;
  const double voxel = bench::takeOption(argc, argv, "--voxel", 0, rest);
  std::vector<char*> rest2, rest3;
  const bool tubes = bench::takeOption(int(rest.size()), rest.data(), "--tubes", 1, rest2) != 0;
  const int samples = int(bench::takeOption(int(rest2.size()), rest2.data(), "--samples", 3, rest3));
  std::vector<char*> rest4;
  const bool decimated = bench::takeOption(int(rest3.size()), rest3.data(), "--decimate", 0, rest4) != 0;
  std::vector<char*> rest5;
  const double slivers = bench::takeOption(int(rest4.size()), rest4.data(), "--slivers", 0, rest5);
  std::vector<char*> rest6;
  const double max_angle = bench::takeOption(int(rest5.size()), rest5.data(), "--max-angle", 0, rest6);
  std::vector<char*> rest7;
  const bool nets = bench::takeOption(int(rest6.size()), rest6.data(), "--nets", 1, rest7) != 0;
  std::vector<char*> rest8;
  const double ring_spacing = bench::takeOption(int(rest7.size()), rest7.data(), "--ring-spacing", 8, rest8);
  std::vector<char*> rest9;
  const bool remesh = bench::takeOption(int(rest8.size()), rest8.data(), "--remesh", 0, rest9) != 0;
  const auto args = bench::parseFileArgs(int(rest9.size()), rest9.data());
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
    TubeSurfaceReport trep;
    const auto t0 = std::chrono::steady_clock::now();
    SurfaceMesh m;
    if (tubes) {
      TubeSurfaceOptions to;
      to.junction = o;
      to.junction.samples_across = samples;
      to.decimate = decimated;
      to.decimation.sliver_deg = slivers;
      to.decimation.obtuse_deg = max_angle;
      to.nets = nets;
      to.ring_spacing_radii = ring_spacing;
      to.remesh = remesh;
      m = tubeSurface(t, to, &trep);
      rep.voxel_mm = trep.finest_step_mm;
    } else {
      m = vesselSurface(t, o, &rep);
    }
    const double s = bench::millisecondsSince(t0) / 1e3;
    if (const char* dump = std::getenv("MESH_DUMP")) {
      std::ofstream os(dump, std::ios::binary);
      meshWriter("off")(os, m);
    }
    const auto topo = meshTopology(m);
    int genus0 = 0;
    for (std::size_t k = 0; k < topo.tree_euler.size(); ++k) genus0 += topo.tree_components[k] == 1 && topo.tree_euler[k] == 2;
    std::printf("%-34s %9lld %9.4f %10.2f %12zu %10.0f %5d/%-2zu %9.0f\n", f.c_str(), (long long)segments, rep.voxel_mm, s, m.triangles.size(),
                double(m.triangles.size()) / double(segments), genus0, topo.tree_euler.size(), peakRssBytes() / 1048576.0);
    std::printf("  boundary %lld, non-manifold %lld, misoriented %lld, degenerate %lld, volume %.4f mm3, euler", (long long)topo.boundary_edges,
                (long long)topo.nonmanifold_edges, (long long)topo.misoriented_edges, (long long)topo.degenerate_triangles, topo.volume_mm3);
    for (auto e : topo.tree_euler) std::printf(" %lld", (long long)e);
    if (tubes)
      std::printf(
          "\n  tubes %lld of %lld vessels, clusters %lld (largest %lld vessels), contour %lld (of %lld contoured) + tube %lld triangles, fallbacks "
          "%lld, parts cut again %lld",
          (long long)trep.tubes, (long long)trep.vessels, (long long)trep.clusters, (long long)trep.largest_cluster_vessels,
          (long long)trep.contour_triangles, (long long)trep.contoured_triangles, (long long)trep.tube_triangles, (long long)trep.fallbacks,
          (long long)trep.cut_retries);
    if (tubes) std::printf(", netted parts %lld", (long long)trep.netted);
    if (tubes && slivers > 0) std::printf(", slivers repaired %lld", (long long)trep.slivers_repaired);
    if (tubes && remesh) std::printf(", remeshed: %lld splits, %lld changes", (long long)trep.remesh_splits, (long long)trep.remesh_changes);
    if (tubes) std::printf(", rounds %lld (largest part meshed again: %lld vessels)", (long long)trep.rounds, (long long)trep.largest_remeshed);
    std::printf("\n");
  }
}
