#include "core/memory.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>

namespace angiosynth {

std::uint64_t physicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page) : (8ULL << 30);
}

std::uint64_t defaultMemoryLimitBytes() { return physicalMemoryBytes() / 4 * 3; }

std::string formatBytes(std::uint64_t b) {
  char buf[64];
  if (b >= (1ULL << 30))
    std::snprintf(buf, sizeof buf, "%.2f GiB", b / double(1ULL << 30));
  else
    std::snprintf(buf, sizeof buf, "%.1f MiB", b / double(1ULL << 20));
  return buf;
}

std::uint64_t peakRssBytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<std::uint64_t>(u.ru_maxrss) * 1024ULL;
}

}  // namespace angiosynth
