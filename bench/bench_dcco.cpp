// DCCO growth time and memory (Maso Talou et al. 2021): one volume-cost stage with Pries' viscosity, θ ≥ 20°
// and Δv = 7 in a 1 cm sphere fed by a 0.5 mm artery (examples/dcco_sphere_pries_3d.toml):
//   bench_dcco [N ...] [--threads T]
// One line per N: seconds, µs per terminal, peak RSS, final checks; then the time exponent
// between consecutive sizes (target ≤ 1.3 from 2k to 8k terminals).
#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include "core/memory.hpp"
#include "grow/dcco/grower.hpp"
#include "physics/hemodynamics.hpp"

using namespace angiosynth;

int main(int argc, char** argv) {
  std::vector<long> sizes;
  int threads = 0;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
      threads = std::atoi(argv[++i]);
    else
      sizes.push_back(std::atol(argv[i]));
  }
  if (sizes.empty()) sizes = {1000, 2000, 4000, 8000};
  std::unique_ptr<tbb::global_control> gc;
  if (threads > 0) gc = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  const auto world = GrowthDomain::analytic(DomainShape::Sphere, 10, 0.1);
  std::printf("%9s %9s %12s %10s %6s %6s %8s %12s\n", "terminals", "time (s)", "us/terminal", "peak MiB", "pairs", "short", "visc it", "volume mm3");
  double last_t = 0;
  long last_n = 0;
  for (long n : sizes) {
    DccoOptions o;
    o.root_mm = world.defaultRoot();
    o.root_radius = 0.5;
    o.flow = 2 * 1000.0 / 60.0;  // 2 mL/min
    o.viscosity.model = ViscosityModel::Pries;
    o.world = &world;
    DccoStage st;
    st.name = "volume";
    st.vessels = st.terminals = &world;
    st.terminal_count = n;
    st.theta_min = 20;
    st.theta_max = 160;
    o.stages = {st};
    GrowthReport rep;
    DccoReport dr;
    const auto t0 = std::chrono::steady_clock::now();
    const auto tree = growDcco(o, rep, dr);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%9ld %9.3f %12.1f %10.1f %6lld %6lld %8lld %12.3f", n, s, s / n * 1e6, peakRssBytes() / 1048576.0, (long long)rep.intersecting_pairs,
                (long long)dr.short_segments, (long long)dr.viscosity_iterations, treeVolume(tree));
    if (last_n > 0) std::printf("   exponent %.2f", std::log(s / last_t) / std::log(double(n) / last_n));
    std::printf("\n");
    std::fflush(stdout);
    last_t = s;
    last_n = n;
  }
}
