#pragma once
// The keys every parameter file may hold besides its method's ([image], [curves], [degrade],
// [output], seed), and the references and templates `angiosynth params` and `init` print.
#include <filesystem>
#include <string>
#include <vector>

#include "grow/method.hpp"

namespace angiosynth {

// Table "" is the top level.
const std::vector<MethodParam>& commonParams();

// Every key of `method` (nullptr: of every method) and the common keys: table, key, unit, default
// and meaning, one line each.
std::string parameterReference(const GrowthMethod* method);

// A parameter file `file` for `method` that runs as it is: a shipped example with its comments,
// and every other key commented out at its default in the table it belongs to, each
// `key = value` line one the reader takes when uncommented alone (checked here; keys whose
// default is a rule are described instead). `data_file`, when not empty after the call, must be
// written beside it with `data_content` (vascusynth: a uniform demand map), under the name the
// template gives it (`<stem>_demand.txt`); the check reads it when it exists.
std::string parameterTemplate(const GrowthMethod& method, const std::filesystem::path& file, std::string& data_file, std::string& data_content);

}  // namespace angiosynth
