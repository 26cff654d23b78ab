#include "files/staged_directory.hpp"

#include <algorithm>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "core/interrupt_cleanup.hpp"
#include "files/output_guard.hpp"
#include "files/text_file.hpp"

namespace angiosynth {

namespace fs = std::filesystem;

namespace {

constexpr const char* kStagingMarker = ".angiosynth-staging";

bool isEmptyDirectory(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec) && fs::is_empty(p, ec);
}

// Staging directories of this target left by processes of this host that were killed.
void removeStaleStaging(const fs::path& parent, const std::string& prefix) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(parent, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) != 0 || !fs::exists(e.path() / kStagingMarker)) continue;
    if (stagingOwnerIsGone(name.substr(prefix.size()))) fs::remove_all(e.path(), ec);
  }
}

std::vector<std::string> filesBelow(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (!e.is_directory()) {
      const std::string rel = fs::relative(e.path(), dir).generic_string();
      if (rel != kStagingMarker) out.push_back(rel);
    }
  std::sort(out.begin(), out.end());
  return out;
}

void writeRecord(const fs::path& file, const std::vector<std::string>& files) {
  nlohmann::ordered_json j{
      {"written_by", "angiosynth"}, {"note", "files angiosynth wrote here; a rerun replaces or removes only these"}, {"files", files}};
  writeTextFile(file, [&](std::ostream& o) { o << j.dump(2) << "\n"; });
}

}  // namespace

std::vector<std::string> recordedOutputFiles(const fs::path& dir) {
  std::ifstream in(dir / kOutputRecord);
  if (!in) return {};
  const auto j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  std::vector<std::string> out;
  if (!j.is_object() || !j.contains("files") || !j["files"].is_array()) return out;
  for (const auto& f : j["files"])
    if (f.is_string() && isConfinedRelativePath(f.get<std::string>())) out.push_back(f.get<std::string>());
  return out;
}

StagedDirectory::StagedDirectory(fs::path target, ExistingOutput existing, const std::vector<fs::path>& inputs, const std::string& what)
    : target_(std::move(target)) {
  if (target_.has_relative_path() && target_.filename().empty()) target_ = target_.parent_path();
  checkOutputPath(target_, inputs, what);
  std::error_code ec;
  if (fs::exists(target_, ec) && !isEmptyDirectory(target_)) {
    const bool ours = fs::exists(target_ / kOutputRecord, ec);
    if (existing == ExistingOutput::Refuse)
      throw InputError(target_.string(), 0,
                       std::string("output directory exists and is not empty; choose another ") + what +
                           (ours ? " or add --force (it replaces only the files angiosynth wrote there)" : ""));
    if (existing == ExistingOutput::ReplaceOwn && !ours)
      throw InputError(target_.string(), 0,
                       std::string("holds files angiosynth did not write (it has no ") + kOutputRecord +
                           "); --force replaces only earlier angiosynth outputs: choose a new or empty directory");
  }
  const fs::path parent = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
  fs::create_directories(parent, ec);
  // Built by appending: GCC 12 misreads `"." + std::string` as an overlapping copy (-Wrestrict).
  std::string prefix(1, '.');
  prefix += target_.filename().string();
  prefix += ".tmp-";
  removeStaleStaging(parent, prefix);
  // A new directory of our own: a leftover of a process that had this pid is ours to remove
  // (it has the marker); anything else of that name is left alone and another name taken.
  for (int k = 0;; ++k) {
    std::string name = prefix + stagingSuffix();
    if (k > 0) name += '-', name += std::to_string(k);
    staging_ = parent / name;
    const auto status = fs::symlink_status(staging_, ec);
    if (fs::exists(status)) {
      if (k == 0 && fs::is_directory(status) && fs::exists(staging_ / kStagingMarker, ec))
        fs::remove_all(staging_, ec);
      else
        continue;
    }
    ec.clear();
    if (fs::create_directory(staging_, ec)) break;
    if (ec != std::errc::file_exists || k > 64) throw InputError(parent.string(), 0, "cannot create an output directory here: " + ec.message());
  }
  registerStaging(staging_);
  std::ofstream(staging_ / kStagingMarker).put('\n');
}

StagedDirectory::~StagedDirectory() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
  unregisterStaging(staging_);
}

void StagedDirectory::commit() {
  std::error_code ec;
  const std::vector<std::string> written = filesBelow(staging_);
  fs::remove(staging_ / kStagingMarker, ec);
  if (!fs::exists(target_, ec) || isEmptyDirectory(target_)) {
    // A new output appears whole: the record goes in, then one rename.
    writeRecord(staging_ / kOutputRecord, written);
    fs::remove(target_, ec);  // an empty directory only
    ec.clear();
    fs::rename(staging_, target_, ec);
    if (ec) throw InputError(target_.string(), 0, "cannot move the finished output into place: " + ec.message());
    committed_ = true;
    unregisterStaging(staging_);
    return;
  }
  // An existing directory: file by file, each replaced by one rename.
  const std::vector<std::string> before = recordedOutputFiles(target_);
  for (const auto& rel : written) {
    const fs::path to = target_ / rel;
    fs::create_directories(to.parent_path(), ec);
    if (fs::is_directory(to, ec)) throw InputError(to.string(), 0, "is a directory where angiosynth writes a file; move it away and run again");
    fs::rename(staging_ / rel, to, ec);
    if (ec) throw InputError(to.string(), 0, "cannot move the finished file into place: " + ec.message());
  }
  const std::set<std::string> now(written.begin(), written.end());
  for (const auto& rel : before) {
    if (now.count(rel)) continue;
    const fs::path old = target_ / rel;
    if (!fs::is_regular_file(fs::symlink_status(old, ec))) continue;
    fs::remove(old, ec);
    // Directories the earlier run made, once empty (remove() leaves non-empty ones).
    for (fs::path d = old.parent_path(); d != target_ && isWithin(d, target_); d = d.parent_path())
      if (!fs::remove(d, ec)) break;
  }
  const fs::path record_tmp = target_ / (std::string(kOutputRecord) + ".tmp-" + stagingSuffix());
  writeRecord(record_tmp, written);
  fs::rename(record_tmp, target_ / kOutputRecord, ec);
  committed_ = true;
  fs::remove_all(staging_, ec);
  unregisterStaging(staging_);
}

}  // namespace angiosynth
