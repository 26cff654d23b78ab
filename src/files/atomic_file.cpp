#include "files/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>

#include "core/error.hpp"
#include "core/interrupt_cleanup.hpp"

namespace angiosynth {

namespace fs = std::filesystem;

namespace {

// renameat2's RENAME_NOREPLACE where the file system has it, else a hard link (which fails if
// the target exists) and the temporary's removal.
bool renameNoReplace(const fs::path& from, const fs::path& to, int& error) {
#ifdef RENAME_NOREPLACE
  if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return true;
  if (errno != EINVAL && errno != ENOSYS) {
    error = errno;
    return false;
  }
#endif
  if (::link(from.c_str(), to.c_str()) != 0) {
    error = errno;
    return false;
  }
  ::unlink(from.c_str());
  return true;
}

constexpr std::string_view kTemporaryMarker = ".tmp-angiosynth-";

// The owner of a temporary's name ".NAME.tmp-angiosynth-HOST-PID-RANDOM", as "HOST-PID".
std::string temporaryOwner(const std::string& name) {
  const auto marker = name.rfind(kTemporaryMarker);
  const auto last_dash = name.rfind('-');
  if (name.empty() || name[0] != '.' || marker == std::string::npos || last_dash == std::string::npos) return {};
  const auto owner_at = marker + kTemporaryMarker.size();
  if (last_dash <= owner_at) return {};
  return name.substr(owner_at, last_dash - owner_at);
}

}  // namespace

int removeAbandonedTemporaries(const fs::path& dir, const std::string& target_name) {
  int removed = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (!target_name.empty() && name.rfind("." + target_name + std::string(kTemporaryMarker), 0) != 0) continue;
    const std::string owner = temporaryOwner(name);
    std::error_code type_ec;
    if (owner.empty() || !e.is_regular_file(type_ec) || e.is_symlink(type_ec) || !stagingOwnerIsGone(owner)) continue;
    std::error_code rm;
    if (fs::remove(e.path(), rm)) ++removed;
  }
  return removed;
}

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  if (target_.empty() || !target_.has_filename()) throw InputError(target_.string(), 0, "is not a file name; give a file such as out/scores.json");
  const fs::path dir = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(target_.string(), 0, "its directory " + dir.string() + " does not exist; create it first");
  removeAbandonedTemporaries(dir, target_.filename().string());
  std::random_device entropy;
  std::mt19937_64 pick((std::uint64_t(entropy()) << 32) ^ entropy() ^ std::uint64_t(::getpid()));
  for (int attempt = 0; attempt < 64; ++attempt) {
    char suffix[24];
    std::snprintf(suffix, sizeof suffix, "%016llx", static_cast<unsigned long long>(pick()));
    // Built by appending: GCC 12 misreads `"." + std::string` as an overlapping copy (-Wrestrict).
    std::string name(1, '.');
    name += target_.filename().string();
    name += kTemporaryMarker;
    name += stagingSuffix();
    name += '-';
    name += suffix;
    temporary_ = dir / name;
    const int fd = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0) {
      if (errno == EEXIST) continue;
      throw InputError(target_.string(), 0, std::string("cannot create a file in ") + dir.string() + ": " + std::strerror(errno));
    }
    registerStaging(temporary_);
    stream_ = ::fdopen(fd, "wb");
    if (!stream_) {
      ::close(fd);
      break;
    }
    return;
  }
  std::error_code rm;
  if (!temporary_.empty() && !stream_) fs::remove(temporary_, rm), unregisterStaging(temporary_);
  throw InputError(target_.string(), 0, "cannot create a temporary file beside it");
}

AtomicFile::~AtomicFile() {
  if (stream_) std::fclose(stream_);
  if (!committed_) {
    ::unlink(temporary_.c_str());
    unregisterStaging(temporary_);
  }
}

void AtomicFile::commit(bool replace) {
  const bool written = std::fflush(stream_) == 0 && !std::ferror(stream_) && ::fsync(::fileno(stream_)) == 0;
  const bool closed = std::fclose(stream_) == 0;
  stream_ = nullptr;
  if (!written || !closed) throw InputError(target_.string(), 0, "cannot write this file (disk full or no permission?)");
  int error = 0;
  const bool moved =
      replace ? ::rename(temporary_.c_str(), target_.c_str()) == 0 || ((error = errno), false) : renameNoReplace(temporary_, target_, error);
  if (!moved)
    throw InputError(target_.string(), 0,
                     error == EEXIST ? std::string("exists; angiosynth does not replace it")
                                     : std::string("cannot move the finished file into place: ") + std::strerror(error));
  committed_ = true;
  unregisterStaging(temporary_);
}

void writeFileAtomically(const fs::path& file, std::string_view bytes, bool replace) {
  AtomicFile f(file);
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), f.stream()) != bytes.size())
    throw InputError(file.string(), 0, "cannot write this file (disk full or no permission?)");
  f.commit(replace);
}

}  // namespace angiosynth
