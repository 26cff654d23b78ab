#include "io/graph_formats.hpp"

#include "io/graph_writers.hpp"
#include "io/network_files.hpp"

namespace angiosynth {
namespace {

constexpr GraphFile kCsv[] = {{"nodes", ".csv", "nodes_csv", &writeNodesCsv}, {"edges", ".csv", "edges_csv", &writeEdgesCsv}};
constexpr GraphFile kVtp[] = {{"centerlines", ".vtp", "vtp", &writeVtp}};
constexpr GraphFile kSwc[] = {{"tree", ".swc", "swc", &writeSwc}};
constexpr GraphFile kCco[] = {{"tree", ".cco", "cco", &writeCco}};
constexpr GraphFile kGraphml[] = {{"tree", ".graphml", "graphml", &writeGraphml}};

const GraphFormat kGraphFormats[] = {
    {"csv", "VesselGraph-style node and edge tables", kCsv},
    {"vtp", "VTK PolyData centrelines", kVtp},
    {"swc", "SWC rows", kSwc},
    {"graphml", "GraphML for NetworkX", kGraphml},
    {"cco", "VItA's .cco tree", kCco},
};

}  // namespace

std::span<const GraphFormat> graphFormats() { return kGraphFormats; }

const GraphFormat* findGraphFormat(std::string_view name) {
  for (const auto& f : kGraphFormats)
    if (f.name == name) return &f;
  return nullptr;
}

std::vector<std::string> graphFormatNames() {
  std::vector<std::string> names;
  for (const auto& f : kGraphFormats) names.emplace_back(f.name);
  return names;
}

std::string graphFormatSummary() {
  std::string s;
  for (const auto& f : kGraphFormats) s += (s.empty() ? "" : ", ") + std::string(f.name) + " (" + std::string(f.meaning) + ")";
  return s;
}

}  // namespace angiosynth
