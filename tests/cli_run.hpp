#pragma once
// Running the angiosynth executable from tests, and reading files back.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

struct Run {
  int code;
  std::string err;
};

// Runs a script with Debian's interpreter in `dir` (nibabel and NetworkX come from Debian
// packages; the python3 first on PATH may be another installation); returns stdout and stderr.
inline std::string debianPython(const std::string& script, const std::filesystem::path& dir) {
  const std::string name = "angiosynth_check_" + std::to_string(::getpid()) + ".py";
  std::ofstream(dir / name) << script;
  std::string out;
  if (FILE* p = popen(("cd '" + dir.string() + "' && /usr/bin/python3 " + name + " 2>&1").c_str(), "r")) {
    char buf[4096];
    while (fgets(buf, sizeof buf, p)) out += buf;
    pclose(p);
  }
  std::filesystem::remove(dir / name);
  return out;
}

inline Run run(const std::string& args, const std::filesystem::path& cwd) {
  const std::filesystem::path err = cwd / "stderr.txt";
  const std::string cmd = "cd '" + cwd.string() + "' && '" + ANGIOSYNTH_EXE + "' " + args + " 2>'" + err.string() + "' >/dev/null";
  const int status = std::system(cmd.c_str());
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

// Runs angiosynth in `cwd` and returns its exit code and everything it printed (stdout and stderr).
inline Run runPrinted(const std::string& args, const std::filesystem::path& cwd) {
  std::string out;
  int status = -1;
  if (FILE* p = popen(("cd '" + cwd.string() + "' && '" + ANGIOSYNTH_EXE + "' " + args + " 2>&1").c_str(), "r")) {
    char buf[4096];
    while (fgets(buf, sizeof buf, p)) out += buf;
    status = pclose(p);
  }
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

// An empty directory for the running test, named after it.
// A directory of its own per test and per process: two suites on one machine (a CI run beside
// a local one) must not delete each other's files.
inline std::filesystem::path freshTestDir(const std::string& prefix) {
  const auto dir = std::filesystem::temp_directory_path() /
                   (prefix + ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// `from` replaced by `to` once; a missing `from` fails the test (the shipped file changed).
inline void replaceOnce(std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' not found";
  if (at != std::string::npos) text.replace(at, from.size(), to);
}

// A shipped input (examples/, tests/data/) whose demand-map paths are made absolute, so that a
// test may write it anywhere.
inline std::string selfContained(const std::filesystem::path& file) {
  std::string t = slurp(file);
  const std::string maps = (std::filesystem::path(ANGIOSYNTH_SOURCE_DIR) / "demand_maps").string();
  for (const std::string rel : {"../../demand_maps", "../demand_maps"})
    for (auto at = t.find(rel); at != std::string::npos; at = t.find(rel, at + maps.size())) t.replace(at, rel.size(), maps);
  return t;
}

}  // namespace
