#pragma once
// The optional graph formats a sample's tree can be written in ([image] graph_formats; GXL, DOT
// and the key points are always written), one entry each: the parameter reader, `angiosynth
// params` and the sample writer read this list. A format is one or more files, each with the
// role sample.json records it under.
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/forest.hpp"
#include "core/vascular_tree.hpp"

namespace angiosynth {

using GraphWriter = void (*)(std::ostream&, const VascularTree&, const std::vector<TreeInfo>&);

struct GraphFile {
  std::string_view stem, extension, role;  // tree + .swc, recorded as "swc"
  GraphWriter write;
};

struct GraphFormat {
  std::string_view name;     // as written in [image] graph_formats
  std::string_view meaning;  // for the parameter reference
  std::span<const GraphFile> files;
};

std::span<const GraphFormat> graphFormats();
// The format of this name, or null.
const GraphFormat* findGraphFormat(std::string_view name);
std::vector<std::string> graphFormatNames();
// "csv (VesselGraph-style node and edge tables), …", for help and references.
std::string graphFormatSummary();

}  // namespace angiosynth
