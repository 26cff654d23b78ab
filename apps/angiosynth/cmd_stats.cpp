// `angiosynth stats SAMPLE|GRAPH`: morphometry of a tree or any vessel graph.
#include <cmath>
#include <cstdio>
#include <iostream>

#include "commands.hpp"
#include "core/error.hpp"
#include "files/atomic_file.hpp"
#include "files/output_guard.hpp"
#include "io/network_files.hpp"
#include "io/volume_writers.hpp"
#include "morphometry/morphometry.hpp"
#include "morphometry/reference.hpp"

namespace angiosynth::cli {
namespace fs = std::filesystem;

CLI::App* addStats(CLI::App& app, StatsArgs& a) {
  auto* c =
      app.add_subcommand("stats",
                         "morphometry of a tree or vessel graph: radii, lengths, tortuosity, bifurcation angles, asymmetry, Murray's exponent by "
                         "radius band, Strahler orders and Horton's ratios, path lengths; per tree and per kind");
  c->add_option("INPUT", a.input, "a sample directory (its nodes.csv and edges.csv are read) or a graph file: .csv, .gxl, .vtp, .swc, .cco")
      ->required();
  c->add_option("--out", a.out,
                "write stats.json, vessels.csv, bifurcations.csv and stats.png (histograms) into this directory (default: print the summary)");
  c->add_option("--murray-bands", a.bands, "lower edges (mm) of the parent-radius bands of Murray's exponent (default 0.1 1)");
  std::string shipped;
  for (const auto& n : shippedMorphometryReferences()) shipped += (shipped.empty() ? "" : ", ") + n;
  c->add_option("--compare", a.compare,
                "compare with published morphometry or another tree: a reference file (data/morphometry/*.toml), a shipped reference by name (" +
                    shipped + "), or another `stats --out` directory (its vessels and bifurcations as samples); repeatable")
      ->take_all();
  c->add_option("--group", a.group, "the group compared: all, kind <kind> or tree <name> (default: the reference's, else all)");
  c->add_flag("--force", a.force, "replace the files of an earlier --out");
  addCommonOptions(*c, a.common);
  return c;
}

int runStats(const StatsArgs& a) {
  const fs::path graph = graphOfInput(a.input);
  MorphometryOptions options;
  if (!a.bands.empty()) {
    for (std::size_t k = 0; k < a.bands.size(); ++k)
      if (!(a.bands[k] > 0) || !std::isfinite(a.bands[k]) || (k > 0 && a.bands[k] <= a.bands[k - 1]))
        throw InputError("--murray-bands", 0, "band edges must be increasing radii in mm, each > 0");
    options.murray_band_edges_mm = a.bands;
  }
  // References first: a bad one is refused before anything is written.
  std::vector<MorphometryReference> references;
  for (const auto& r : a.compare) {
    references.push_back(readMorphometryReference(r));
    if (!a.group.empty()) references.back().group = a.group;
  }
  std::vector<OutputFile> outputs;
  if (!a.out.empty()) {
    for (const char* f : {"stats.json", "vessels.csv", "bifurcations.csv", "stats.png"}) outputs.push_back({fs::path(a.out) / f, "--out"});
    if (!references.empty()) outputs.push_back({fs::path(a.out) / "comparison.json", "--out"});
  }
  checkOutputFiles(outputs, {graph}, a.force);
  const ExistingNetwork net = readNetwork(graph, 1, memoryLimit(a.common));
  Morphometry m = measureTrees(net.tree, net.tree_names, net.tree_kinds, options);
  m.segment_names = net.ids;
  std::vector<MorphometryComparison> comparisons;
  for (const auto& r : references) comparisons.push_back(compareMorphometry(m, r));
  if (!a.out.empty()) {
    fs::create_directories(a.out);
    auto j = m.toJson();
    j["input"] = graph.string();
    writeFileAtomically(fs::path(a.out) / "stats.json", j.dump(1) + "\n", a.force);
    writeFileAtomically(fs::path(a.out) / "vessels.csv", m.vesselsCsv(), a.force);
    writeFileAtomically(fs::path(a.out) / "bifurcations.csv", m.bifurcationsCsv(), a.force);
    writeFileAtomically(fs::path(a.out) / "stats.png", encodePng(morphometryFigure(m)), a.force);
    if (!comparisons.empty()) {
      nlohmann::ordered_json list = nlohmann::ordered_json::array();
      for (const auto& c : comparisons) list.push_back(c.toJson());
      writeFileAtomically(fs::path(a.out) / "comparison.json",
                          nlohmann::ordered_json{{"input", graph.string()}, {"comparisons", list}}.dump(1) + "\n", a.force);
    }
  }
  if (a.common.quiet) return 0;
  for (const auto& c : comparisons) std::printf("%s\n", c.table().c_str());
  for (const auto& g : m.groups) {
    std::printf("%s: %lld vessels, %lld bifurcations, %lld terminals; Horton ratios branching %.3g, length %.3g, diameter %.3g; Murray exponent %.3g",
                g.name.c_str(), (long long)g.vessels, (long long)g.bifurcations, (long long)g.terminals, g.horton_branching, g.horton_length,
                g.horton_diameter, g.murray_fitted);
    for (const auto& b : g.murray_bands)
      if (b.bifurcations) std::printf(" (%.3g for r %.3g–%.3g mm, %lld)", b.fitted_exponent, b.lower_mm, b.upper_mm, (long long)b.bifurcations);
    std::printf("\n");
    for (const char* key : {"radius_mm", "length_mm", "length_over_radius", "distance_metric", "angle_large_deg", "angle_small_deg",
                            "angle_between_deg", "asymmetry", "murray_exponent", "generation", "strahler"}) {
      const auto it = g.summaries.find(key);
      if (it == g.summaries.end()) continue;
      const Summary& s = it->second;
      std::printf("  %-22s median %-10.4g mean %-10.4g sd %-10.4g p05 %-10.4g p95 %.4g\n", key, s.median, s.mean, s.sd, s.p05, s.p95);
    }
  }
  return 0;
}

}  // namespace angiosynth::cli
