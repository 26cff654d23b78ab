// CCO forests: two benchmarks.
//   bench_cco_forest split [seeds]   two equiradial inlets on opposite sides of a disc (Maso Talou et al. 2021
//                                     Fig. 3, volume cost), 1000 terminals: the flow share of each
//                                     inlet per seed, its mean and spread
//   bench_cco_forest av [N] [seeds]  an artery and a vein, N terminals each (default 4000), in the
//                                     100 cm³ sphere of examples/cco_artery_vein_3d.toml: growth
//                                     time, final checks
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "core/units.hpp"
#include "core/memory.hpp"
#include "grow/cco/grower.hpp"

using namespace angiosynth;

namespace {

CcoInlet inlet(const Vec3& root, int system, double p_root, double p_term) {
  CcoInlet in;
  in.root_mm = root;
  in.system = system;
  in.root_pressure = p_root;
  in.terminal_pressure = p_term;
  return in;
}

CcoOptions options(long n, std::uint64_t seed, double flow_ml_min) {
  CcoOptions o;
  o.terminals = n;
  o.physics.perfusion_flow = flow_ml_min * 1000.0 / 60.0;
  o.physics.perfusion_pressure = 100 * kPaPerMmHg;
  o.physics.terminal_pressure = 60 * kPaPerMmHg;
  o.physics.total_terminals = n;
  o.seed = seed;
  return o;
}

double seconds(std::chrono::steady_clock::time_point t0) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "av";
  if (mode == "split") {
    const int seeds = argc > 2 ? std::atoi(argv[2]) : 10;
    const auto d = GrowthDomain::analytic(DomainShape::Disc, 20, 0.05);  // examples/cco_two_inlets_2d.toml
    const Vec3 c = d.center();
    const std::vector<CcoInlet> inlets{inlet(c + Vec3(-20, 0, 0), 0, 100 * kPaPerMmHg, 60 * kPaPerMmHg),
                                       inlet(c + Vec3(20, 0, 0), 0, 100 * kPaPerMmHg, 60 * kPaPerMmHg)};
    std::printf("%4s %10s %10s %12s %8s %6s\n", "seed", "left", "right", "larger share", "time s", "pairs");
    double sum = 0, sum2 = 0;
    for (int seed = 1; seed <= seeds; ++seed) {
      GrowthReport rep;
      const auto t0 = std::chrono::steady_clock::now();
      const auto trees = growCcoForest(d, options(1000, seed, 125), inlets, rep);
      const double left = trees[0].terminalCount() / 1000.0, right = trees[1].terminalCount() / 1000.0;
      const double larger = std::max(left, right);
      sum += left, sum2 += left * left;
      std::printf("%4d %10.3f %10.3f %12.3f %8.3f %6lld\n", seed, left, right, larger, seconds(t0), (long long)rep.intersecting_pairs);
    }
    const double mean = sum / seeds, sd = std::sqrt(std::max(0.0, sum2 / seeds - mean * mean));
    std::printf("left inlet's share of the flow: mean %.3f, standard deviation %.3f over %d seeds\n", mean, sd, seeds);
    return 0;
  }
  const long n = argc > 2 ? std::atol(argv[2]) : 4000;
  const int seeds = argc > 3 ? std::atoi(argv[3]) : 1;
  const double radius = std::cbrt(3 * 1e5 / (4 * M_PI));
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, radius, 0.3);
  const Vec3 c = d.center();
  const double y = std::sqrt(radius * radius - 25);
  const std::vector<CcoInlet> inlets{inlet(c + Vec3(-5, y, 0), 0, 100 * kPaPerMmHg, 60 * kPaPerMmHg),
                                     inlet(c + Vec3(5, y, 0), 1, 5 * kPaPerMmHg, 20 * kPaPerMmHg)};
  std::printf("%4s %9s %9s %10s %6s %6s %8s %9s\n", "seed", "terminals", "time (s)", "peak MiB", "pairs", "short", "repaired", "lenient");
  for (int seed = 1; seed <= seeds; ++seed) {
    GrowthReport rep;
    const auto t0 = std::chrono::steady_clock::now();
    growCcoForest(d, options(n, seed, 500), inlets, rep);
    std::printf("%4d %9ld %9.3f %10.1f %6lld %6lld %8lld %9lld\n", seed, 2 * n, seconds(t0), peakRssBytes() / 1048576.0,
                (long long)rep.intersecting_pairs, (long long)rep.short_segments, (long long)rep.repaired_terminals,
                (long long)rep.lenient_connections);
    std::fflush(stdout);
  }
}
