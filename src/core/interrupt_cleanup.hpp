#pragma once
// Staging directories are removed when the run is interrupted (SIGINT, SIGTERM, SIGHUP), not only
// when it fails: a Ctrl-C or a scheduler's time limit must not leave `.NAME.tmp-…` behind.
// The signals are taken by one thread with sigwait, so the removal runs in ordinary code rather
// than in an async-signal handler. A SIGKILL cannot be caught: its leftovers are removed by the
// next run (see StagedDirectory).
#include <filesystem>

namespace angiosynth {

// Blocks the signals in the calling thread (and so in every thread started after it) and starts
// the thread that waits for them. Call first thing in main(); later calls do nothing.
void installInterruptCleanup();

// Registers a directory the program is writing; removed (recursively) on an interrupt.
void registerStaging(const std::filesystem::path& dir);
void unregisterStaging(const std::filesystem::path& dir);

// Leftover staging directories are named <prefix><host>-<pid>; this process's suffix.
std::string stagingSuffix();
// Whether a staging suffix names a process of this host that no longer runs.
bool stagingOwnerIsGone(const std::string& suffix);

}  // namespace angiosynth
