// `angiosynth params [METHOD]` and `angiosynth init [METHOD] FILE`: the key reference and a
// template that runs as it is, from the program itself.
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "core/error.hpp"
#include "files/atomic_file.hpp"
#include "config/common_params.hpp"

namespace angiosynth::cli {

namespace {

const GrowthMethod& methodNamed(const std::string& name) {
  const GrowthMethod* m = findGrowthMethod(name);
  if (!m) throw InputError("", 0, "method '" + name + "' is not available; allowed: " + growthMethodNames());
  return *m;
}

// Never replaces a file: a template is a starting point, not an output to refresh. Written
// whole through an exclusively created temporary, and moved into place only if the name is
// still free then.
void writeNew(const std::filesystem::path& file, const std::string& text) {
  if (std::filesystem::exists(std::filesystem::symlink_status(file)))
    throw InputError(file.string(), 0, "exists; init writes new files only (choose another name)");
  writeFileAtomically(file, text, /*replace=*/false);
}

}  // namespace

CLI::App* addParams(CLI::App& app, ParamsArgs& a) {
  auto* c = app.add_subcommand("params",
                               "print every key of a parameter file with its unit, default and meaning "
                               "(the common keys and METHOD's, or every method's)");
  c->add_option("METHOD", a.method, "a growth method (see `angiosynth methods`)");
  return c;
}

int runParams(const ParamsArgs& a) {
  std::cout << parameterReference(a.method.empty() ? nullptr : &methodNamed(a.method));
  return 0;
}

CLI::App* addInit(CLI::App& app, InitArgs& a) {
  auto* c = app.add_subcommand("init",
                               "write a commented parameter file that runs as it is: a shipped example of METHOD "
                               "(default cco) and every other key at its default; never replaces a file");
  c->add_option("ARGS", a.args, "[METHOD] FILE")->expected(1, 2)->required();
  return c;
}

int runInit(const InitArgs& a) {
  const std::string method = a.args.size() == 2 ? a.args[0] : "cco";
  const std::filesystem::path file = a.args.back();
  if (file.empty() || !file.has_filename() || std::filesystem::is_directory(file))
    throw InputError("", 0, "FILE '" + file.string() + "' is not a file name; give the parameter file to write, such as my_tree.toml");
  const GrowthMethod& m = methodNamed(method);
  std::string data_file, data;
  std::string text = parameterTemplate(m, file, data_file, data);
  const std::filesystem::path data_path = file.parent_path() / data_file;
  if (!data_file.empty()) {
    // The template's keys are checked against its data, so that is written first (and removed
    // again if the template cannot be).
    if (std::filesystem::exists(data_path)) throw InputError(data_path.string(), 0, "exists; init writes new files only (choose another name)");
    if (std::filesystem::exists(std::filesystem::symlink_status(file)))
      throw InputError(file.string(), 0, "exists; init writes new files only (choose another name)");
    writeNew(data_path, data);
    try {
      text = parameterTemplate(m, file, data_file, data);
      writeNew(file, text);
    } catch (...) {
      std::error_code ec;
      std::filesystem::remove(data_path, ec);
      throw;
    }
  } else {
    writeNew(file, text);
  }
  std::cerr << "wrote " << file.string() << (data_file.empty() ? "" : " and " + data_path.string()) << "; run: angiosynth generate " << file.string()
            << "\n";
  return 0;
}

}  // namespace angiosynth::cli
