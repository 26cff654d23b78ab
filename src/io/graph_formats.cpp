#include "io/graph_formats.hpp"

#include "io/format_lists.hpp"
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
    {"csv", "VesselGraph-style node and edge tables", kCsv}, {"vtp", "VTK PolyData centrelines", kVtp}, {"swc", "SWC rows", kSwc},
    {"graphml", "GraphML for NetworkX", kGraphml},           {"cco", "VItA's .cco tree", kCco},
};

}  // namespace

std::span<const GraphFormat> graphFormats() { return kGraphFormats; }

const GraphFormat* findGraphFormat(std::string_view name) { return findFormat(graphFormats(), name); }
std::vector<std::string> graphFormatNames() { return formatNames(graphFormats()); }
std::string graphFormatSummary() { return formatSummary(graphFormats()); }

}  // namespace angiosynth
