#include "io/staged_directory.hpp"

#include <unistd.h>

#include "core/error.hpp"

namespace angiosynth {

namespace fs = std::filesystem;

StagedDirectory::StagedDirectory(fs::path target, bool replace) : target_(std::move(target)), replace_(replace) {
  if (target_.filename().empty()) target_ = target_.parent_path();
  if (fs::exists(target_) && !replace_ && !(fs::is_directory(target_) && fs::is_empty(target_)))
    throw InputError(target_.string(), 0, "output directory exists and is not empty; choose another --out or add --force");
  const fs::path parent = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(parent, ec);
  staging_ = parent / ("." + target_.filename().string() + ".tmp-" + std::to_string(::getpid()));
  fs::remove_all(staging_, ec);
  if (!fs::create_directory(staging_, ec) || ec)
    throw InputError(parent.string(), 0, "cannot create an output directory here: " + ec.message());
}

StagedDirectory::~StagedDirectory() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

void StagedDirectory::commit() {
  std::error_code ec;
  if (fs::exists(target_)) fs::remove_all(target_, ec);
  fs::rename(staging_, target_, ec);
  if (ec) throw InputError(target_.string(), 0, "cannot move the finished output into place: " + ec.message());
  committed_ = true;
}

}  // namespace angiosynth
