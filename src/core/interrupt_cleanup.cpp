#include "core/interrupt_cleanup.hpp"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <mutex>
#include <set>
#include <string>
#include <thread>

namespace angiosynth {
namespace {

std::mutex& registryMutex() {
  static std::mutex m;
  return m;
}
std::set<std::filesystem::path>& registry() {
  static std::set<std::filesystem::path> r;
  return r;
}

sigset_t handledSignals() {
  sigset_t s;
  sigemptyset(&s);
  sigaddset(&s, SIGINT);
  sigaddset(&s, SIGTERM);
  sigaddset(&s, SIGHUP);
  return s;
}

std::string hostName() {
  char host[256] = {0};
  ::gethostname(host, sizeof host - 1);
  std::string h(host);
  for (char& c : h)
    if (c == '/' || c == '-' || c == '.') c = '_';
  return h.empty() ? "host" : h;
}

}  // namespace

void installInterruptCleanup() {
  static std::once_flag once;
  std::call_once(once, [] {
    const sigset_t s = handledSignals();
    pthread_sigmask(SIG_BLOCK, &s, nullptr);
    std::thread([s] {
      int sig = 0;
      while (sigwait(&s, &sig) != 0) {}
      {
        std::lock_guard<std::mutex> lock(registryMutex());
        for (const auto& d : registry()) {
          std::error_code ec;
          std::filesystem::remove_all(d, ec);
        }
      }
      std::fprintf(stderr, "\nangiosynth: interrupted (signal %d); partial outputs removed\n", sig);
      std::fflush(stderr);
      ::_exit(128 + sig);
    }).detach();
  });
}

void registerStaging(const std::filesystem::path& dir) {
  std::lock_guard<std::mutex> lock(registryMutex());
  registry().insert(dir);
}

void unregisterStaging(const std::filesystem::path& dir) {
  std::lock_guard<std::mutex> lock(registryMutex());
  registry().erase(dir);
}

std::string stagingSuffix() { return hostName() + "-" + std::to_string(::getpid()); }

bool stagingOwnerIsGone(const std::string& suffix) {
  const std::string host = hostName() + "-";
  if (suffix.rfind(host, 0) != 0) return false;  // another machine's: it may still run
  const std::string pid_text = suffix.substr(host.size());
  if (pid_text.empty() || pid_text.find_first_not_of("0123456789") != std::string::npos || pid_text.size() > 9) return false;
  const pid_t pid = static_cast<pid_t>(std::stol(pid_text));
  if (pid == ::getpid()) return false;
  return ::kill(pid, 0) != 0 && errno == ESRCH;
}

}  // namespace angiosynth
