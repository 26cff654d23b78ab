#pragma once
// Memory is estimated before every large allocation, so a map or volume too big for the machine
// is refused with a message instead of an out-of-memory kill halfway through a run.
#include <cstdint>
#include <string>

namespace angiosynth {

// Physical memory of this machine, in bytes.
std::uint64_t physicalMemoryBytes();
// Default ceiling for one run: 75 % of physical memory.
std::uint64_t defaultMemoryLimitBytes();
std::string formatBytes(std::uint64_t bytes);
// Peak resident set size of this process so far, in bytes.
std::uint64_t peakRssBytes();

}  // namespace angiosynth
