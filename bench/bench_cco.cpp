// CCO growth time and memory for N terminals in the Kerautret et al. (OpenCCO) §5 sphere (or the 2D disc):
//   bench_cco [N ...] [--disc] [--threads T] [--max-nu M] [--seed S] [--murray-bands] [--organ-scale] [--parts K]
// One line per N: seconds, µs per terminal, µs per terminal / log2 N, peak RSS, checks.
// --parts K: grown by domain decomposition (a trunk of K terminals, K parts in parallel, the
// join), with the time of each stage and the join's checks.
// --murray-bands: Murray's exponent 3, 2.73, 7/3 below 0.1 mm, to 1 mm, above; also the passes
// the radius–exponent fixed point takes from radii of zero on the grown tree.
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "core/memory.hpp"
#include "grow/cco/decomposition.hpp"
#include "grow/cco/grower.hpp"
#include "physics/hemodynamics.hpp"

using namespace angiosynth;

int main(int argc, char** argv) {
  std::vector<long> sizes;
  bool disc = false, bands = false, organ = false;
  int threads = 0;
  int parts = 0;
  int max_nu = 0;  // ν doubles up to this (0: the default)
  long seed = 1;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--disc"))
      disc = true;
    else if (!std::strcmp(argv[i], "--murray-bands"))
      bands = true;
    else if (!std::strcmp(argv[i], "--organ-scale"))
      organ = true;
    else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc)
      seed = std::atol(argv[++i]);
    else if (!std::strcmp(argv[i], "--max-nu") && i + 1 < argc)
      max_nu = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--parts") && i + 1 < argc)
      parts = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
      threads = std::atoi(argv[++i]);
    else
      sizes.push_back(std::atol(argv[i]));
  }
  if (sizes.empty()) sizes = {1000, 4000};
  std::unique_ptr<tbb::global_control> gc;
  if (threads > 0) gc = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  // Kerautret et al. (OpenCCO) §5 and Karch et al. 1999: 100 cm³ perfused with 500 mL/min (4000 terminals of 0.125 mL/min).
  const double radius = disc ? 50.0 : std::cbrt(3 * 1e5 / (4 * M_PI));
  const auto dom = GrowthDomain::analytic(disc ? DomainShape::Disc : DomainShape::Sphere, radius, radius / 50);
  std::printf("%-7s %9s %9s %12s %16s %10s %6s %6s %9s\n", "domain", "terminals", "time (s)", "us/terminal", "us/term/log2(N)", "peak MiB", "pairs",
              "short", "volume mm3");
  for (long n : sizes) {
    CcoOptions o;
    o.terminals = n;
    if (max_nu > 0) o.max_neighbours = max_nu;
    o.seed = std::uint64_t(seed);
    o.organ_scale = organ;
    o.root_mm = dom.defaultRoot();
    o.physics.perfusion_flow = 500 * 1000.0 / 60.0;  // Karch 1999: 500 mL/min for the whole organ
    o.physics.perfusion_pressure = 100 * 133.322;
    o.physics.terminal_pressure = 60 * 133.322;
    if (bands) {
      o.physics.murray_band_edges = {0.1, 1.0};
      o.physics.murray_band_exponents = {3.0, 2.73, 7.0 / 3.0};
    }
    GrowthReport rep;
    const auto t0 = std::chrono::steady_clock::now();
    const auto since = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    double growth_s = -1;  // until the tree first holds every terminal; the rest is the final check's repair
    const ProgressFn progress = [&](std::int64_t done, std::int64_t total) {
      if (growth_s < 0 && done >= total) growth_s = since();
    };
    CcoDecompositionSummary parts_sum;
    VascularTree tree;
    if (parts > 0) {
      CcoDecompositionOptions d;
      d.cco = o;
      d.parts = parts;
      tree = growCcoDecomposed(dom, d, rep, progress);
      parts_sum = *rep.decomposition;
    } else {
      tree = growCco(dom, o, rep, progress);
    }
    const double s = since();
    std::printf("%-7s %9ld %9.3f %12.1f %16.2f %10.1f %6lld %6lld %9.1f\n", disc ? "disc" : "sphere", n, s, s / n * 1e6,
                s / n * 1e6 / std::log2(double(n)), peakRssBytes() / 1048576.0, (long long)rep.intersecting_pairs, (long long)rep.short_segments,
                treeVolume(tree));
    {
      // The physics of the final tree: the worst relative residual of Murray's law, flow
      // conservation and Poiseuille's drop at any bifurcation.
      PhysicsParameters p = o.physics;
      p.total_terminals = n;
      const MurrayLaw law(p);
      const double k = 8 * p.viscosity / M_PI, drop = std::abs(p.perfusion_pressure - p.terminal_pressure);
      double murray = 0, flow = 0, poiseuille = 0, ratio = 1e300;
      for (std::int32_t i = 1; i < tree.nodeCount(); ++i) {
        ratio = std::min(ratio, tree.length[i] / tree.radius[i]);
        if (tree.isTerminal(i)) continue;
        const auto a = tree.child0[i], b = tree.child1[i];
        if (b < 0) {  // inside a vessel (a part's root on the trunk): one radius and flow
          murray = std::max(murray, std::abs(tree.radius[a] - tree.radius[i]) / tree.radius[i]);
          flow = std::max(flow, std::abs(tree.flow[a] - tree.flow[i]) / tree.flow[i]);
          continue;
        }
        const double g = law.exponentAt(tree.radius[i]);
        const double lhs = std::pow(tree.radius[i], g);
        murray = std::max(murray, std::abs(lhs - std::pow(tree.radius[a], g) - std::pow(tree.radius[b], g)) / lhs);
        flow = std::max(flow, std::abs(tree.flow[i] - tree.flow[a] - tree.flow[b]) / tree.flow[i]);
        for (auto c : {a, b})
          poiseuille = std::max(
              poiseuille, std::abs(tree.pressure[i] - tree.pressure[c] - tree.flow[c] * k * tree.length[c] / std::pow(tree.radius[c], 4)) / drop);
      }
      std::printf("        residuals: Murray %.1e, flow %.1e, Poiseuille %.1e; shortest l/r %.3f\n", murray, flow, poiseuille, ratio);
    }
    if (parts > 0)
      std::printf(
          "        %d parts: trunk %.2f s, parts %.1f s (slowest %.1f s), join %.2f s; terminals %lld, outside %lld; part radii x%.3f-%.3f "
          "of grown, trunk radius <= %.2f of clearance, part pressure share >= %.3f; demand in no part %.4f\n",
          parts, parts_sum.trunk_seconds, parts_sum.parts_seconds, parts_sum.slowest_part_seconds, parts_sum.join_seconds,
          (long long)parts_sum.terminals, (long long)parts_sum.outside_segments, parts_sum.smallest_part_scale, parts_sum.largest_part_scale,
          parts_sum.largest_trunk_radius_share, parts_sum.smallest_part_pressure_share, parts_sum.unreached_share);
    if (bands) {
      auto cold = tree;
      std::fill(cold.radius.begin(), cold.radius.end(), 0.0);
      PhysicsParameters p = o.physics;
      p.total_terminals = n;
      const auto t1 = std::chrono::steady_clock::now();
      const int passes = solveTree(cold, p);
      std::printf("        banded γ: %d passes from radii of zero, %.3f s\n", passes,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
    }
    std::fprintf(stderr,
                 "  draws too close %lld, candidates %lld, unconnectable %lld, relaxations %lld, doublings %lld, kamiya failures %lld, collisions "
                 "%lld, repair rounds %d, repaired %lld; growth %.1f s, repair %.1f s\n",
                 (long long)rep.rejected_too_close, (long long)rep.candidates, (long long)rep.rejected_unreachable,
                 (long long)rep.threshold_relaxations, (long long)rep.neighbour_doublings, (long long)rep.kamiya_failures,
                 (long long)rep.rejected_intersection, rep.repair_rounds, (long long)rep.repaired_terminals, growth_s, s - growth_s);
    for (const auto& x : rep.short_list)
      std::fprintf(stderr, "  short segment left: length %.4g mm, radius %.4g mm, distal (%.4g, %.4g, %.4g)\n", x.length, x.radius, x.distal[0],
                   x.distal[1], x.distal[2]);
    std::fflush(stdout);
  }
}
