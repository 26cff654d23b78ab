#include "files/output_guard.hpp"

#include "core/error.hpp"

namespace angiosynth {

namespace fs = std::filesystem;

namespace {

fs::path normalised(const fs::path& p) {
  std::error_code ec;
  fs::path abs = fs::absolute(p, ec);
  if (ec) abs = p;
  fs::path canon = fs::weakly_canonical(abs, ec);
  return (ec ? abs.lexically_normal() : canon.lexically_normal());
}

fs::path withoutTrailingSlash(fs::path p) {
  if (p.has_relative_path() && p.filename().empty()) p = p.parent_path();
  return p;
}

}  // namespace

bool isWithin(const fs::path& inner, const fs::path& outer) {
  const fs::path in = withoutTrailingSlash(normalised(inner)), out = withoutTrailingSlash(normalised(outer));
  auto i = in.begin();
  for (auto o = out.begin(); o != out.end(); ++o, ++i) {
    if (o->empty()) continue;
    if (i == in.end() || *i != *o) return false;
  }
  return true;
}

bool isConfinedRelativePath(const std::string& rel) {
  if (rel.empty() || rel.find('\0') != std::string::npos) return false;
  const fs::path p(rel);
  if (p.has_root_path()) return false;
  for (const auto& part : p)
    if (part == ".." || part == ".") return false;
  return true;
}

void checkOutputFiles(const std::vector<OutputFile>& outputs, const std::vector<fs::path>& inputs, bool replace) {
  std::error_code ec;
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    const auto& [out, what] = outputs[k];
    if (out.empty()) continue;
    const std::string shown = out.string();
    if (!out.has_filename() || fs::is_directory(out, ec)) throw InputError(what, 0, "'" + shown + "' is a directory; give a file name");
    for (const auto& in : inputs) {
      if (in.empty()) continue;
      const bool same = isWithin(out, in) || (fs::exists(out, ec) && fs::exists(in, ec) && fs::equivalent(out, in, ec));
      if (same) throw InputError(what, 0, "'" + shown + "' is the input " + in.string() + " or lies inside it; allowed: a file elsewhere");
    }
    for (std::size_t j = 0; j < k; ++j) {
      const auto& other = outputs[j];
      if (other.path.empty()) continue;
      const bool same = isWithin(out, other.path) || (fs::exists(out, ec) && fs::exists(other.path, ec) && fs::equivalent(out, other.path, ec));
      if (same) throw InputError(what, 0, "'" + shown + "' is also " + other.what + "; allowed: a file of its own for each output");
    }
    if (fs::exists(fs::symlink_status(out, ec)) && !replace) throw InputError(what, 0, "'" + shown + "' exists; give --force to replace it");
  }
}

void checkOutputPath(const fs::path& out, const std::vector<fs::path>& inputs, const std::string& what) {
  const std::string shown = out.string();
  if (out.empty()) throw InputError(what, 0, "the output directory is empty; give a directory name");
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_directory(out, ec))
    throw InputError(what, 0, "'" + shown + "' is a file, not a directory; give a new or empty directory");
  const fs::path cwd = fs::current_path(ec);
  if (!ec && isWithin(cwd, out))
    throw InputError(what, 0,
                     "'" + shown +
                         "' is the working directory or contains it; angiosynth refuses to write "
                         "there because replacing it could remove your files; give a new subdirectory such as out/run1");
  for (const auto& in : inputs) {
    if (in.empty()) continue;
    if (isWithin(in, out))
      throw InputError(what, 0, "'" + shown + "' contains the input " + in.string() + "; give an output directory that holds none of the inputs");
  }
}

}  // namespace angiosynth
