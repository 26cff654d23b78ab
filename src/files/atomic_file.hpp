#pragma once
// A file written whole or not at all, next to where it goes. The bytes go to a temporary created
// exclusively (O_CREAT | O_EXCL | O_NOFOLLOW: never a file that is there already, never through a
// link) under a unique hidden name in the target's directory; commit() renames it into place. A
// temporary never committed is removed, on an exception or a Ctrl-C (core/interrupt_cleanup);
// one a SIGKILL left is named after its process (.NAME.tmp-angiosynth-HOST-PID-RANDOM), so the
// next writer of the same file, or removeAbandonedTemporaries, removes it once that process is gone.
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace angiosynth {

class AtomicFile {
 public:
  // Throws InputError when the target's directory does not exist or cannot take a new file.
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::FILE* stream() { return stream_; }
  const std::filesystem::path& target() const { return target_; }
  // Moves the finished file into place. `replace` false: the target must not exist, checked by
  // the rename itself (no window in which another process's file could be replaced).
  void commit(bool replace = true);

 private:
  std::filesystem::path target_, temporary_;
  std::FILE* stream_ = nullptr;
  bool committed_ = false;
};

// Removes the temporaries in `dir` (not below it) that AtomicFiles of processes of this host no
// longer running left behind; with `target_name`, only those of that file. Returns how many.
int removeAbandonedTemporaries(const std::filesystem::path& dir, const std::string& target_name = {});

// `bytes` written to `file` through an AtomicFile.
void writeFileAtomically(const std::filesystem::path& file, std::string_view bytes, bool replace = true);

}  // namespace angiosynth
