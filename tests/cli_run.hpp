#pragma once
// Running the angiosynth executable from tests, and reading files back.
#include <gtest/gtest.h>
#include <sys/wait.h>

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

inline Run run(const std::string& args, const std::filesystem::path& cwd) {
  const std::filesystem::path err = cwd / "stderr.txt";
  const std::string cmd = "cd '" + cwd.string() + "' && '" + ANGIOSYNTH_EXE + "' " + args + " 2>'" + err.string() + "' >/dev/null";
  const int status = std::system(cmd.c_str());
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

// An empty directory for the running test, named after it.
inline std::filesystem::path freshTestDir(const std::string& prefix) {
  const auto dir = std::filesystem::temp_directory_path() /
                   (prefix + ::testing::UnitTest::GetInstance()->current_test_info()->name());
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

}  // namespace
