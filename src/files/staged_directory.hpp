#pragma once
// An output directory written safely. Files are written into a hidden sibling directory
// (.NAME.tmp-HOST-PID) and moved into place on commit(); a failed or interrupted run removes only
// that sibling. Every output directory records the files the program wrote in
// .angiosynth-files.json; replacing an output removes only files listed there, so the user's own
// files in it (notes, other results) survive.
#include <filesystem>
#include <string>
#include <vector>

namespace angiosynth {

enum class ExistingOutput {
  Refuse,      // the target must be new or empty
  ReplaceOwn,  // --force: the target may hold an earlier output of angiosynth (it has the record)
  Merge,       // VascuSynth's convention: write our files into any directory, overwriting only them
};

class StagedDirectory {
 public:
  // Throws InputError if the target is refused (see ExistingOutput and checkOutputPath: never the
  // working directory, an input or an ancestor of either). `what` names the option for errors.
  StagedDirectory(std::filesystem::path target, ExistingOutput existing, const std::vector<std::filesystem::path>& inputs,
                  const std::string& what = "--out");
  ~StagedDirectory();
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  const std::filesystem::path& path() const { return staging_; }
  const std::filesystem::path& target() const { return target_; }
  // Moves every staged file into the target (each one atomically), removes files an earlier run
  // recorded that this run did not write, and writes the new record last.
  void commit();

 private:
  std::filesystem::path target_, staging_;
  bool committed_ = false;
};

// The record's name, and the files it lists (relative, confined to `dir`; empty if none).
inline constexpr const char* kOutputRecord = ".angiosynth-files.json";
std::vector<std::string> recordedOutputFiles(const std::filesystem::path& dir);

}  // namespace angiosynth
