#pragma once
// An output directory that appears whole or not at all: files are written into a hidden sibling
// directory which is renamed into place on commit() and removed if the run fails.
#include <filesystem>

namespace angiosynth {

class StagedDirectory {
 public:
  // Throws InputError if `target` exists and is not empty, unless `replace`.
  StagedDirectory(std::filesystem::path target, bool replace);
  ~StagedDirectory();
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  const std::filesystem::path& path() const { return staging_; }
  const std::filesystem::path& target() const { return target_; }
  void commit();

 private:
  std::filesystem::path target_, staging_;
  bool replace_, committed_ = false;
};

}  // namespace angiosynth
