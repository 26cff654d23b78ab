// Space colonisation growth time (Rauch & Harders 2021): the forest of each parameter file, grown 5 times,
// the fastest run reported with the node counts per kind (seed: the file's, else 1):
//   bench_colonisation FILE.toml ... [--threads T]
// Targets: examples/colonisation_fig5_2d.toml ≤ 15 ms, 40k nodes ≤ 0.8 s, the
// retina-like example ≤ 0.5 s.
#include <cstdio>
#include <map>

#include "bench_files.hpp"
#include "core/memory.hpp"

using namespace angiosynth;

int main(int argc, char** argv) {
  const auto args = bench::parseFileArgs(argc, argv);
  std::printf("%-40s %10s %10s %10s %10s %10s %10s\n", "file", "grow ms", "check ms", "nodes", "artery", "vein", "peak MiB");
  for (const auto& f : args.files) {
    const auto run = bench::bestOfFive(f);
    std::map<std::string, std::int64_t> per_kind;
    const auto& t = run.forest.vessels;
    for (std::int32_t i = 0; i < t.nodeCount(); ++i) ++per_kind[run.forest.trees[std::size_t(t.tree[i])].kind];
    std::printf("%-40s %10.2f %10.2f %10d %10lld %10lld %10.1f\n", f.c_str(), run.grow_ms, run.check_ms, t.nodeCount(), (long long)per_kind["artery"],
                (long long)per_kind["vein"], peakRssBytes() / 1048576.0);
  }
}
