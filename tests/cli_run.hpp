#pragma once
// Running the angiosynth executable from tests, and reading files back.
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

Run run(const std::string& args, const std::filesystem::path& cwd) {
  const std::filesystem::path err = cwd / "stderr.txt";
  const std::string cmd = "cd '" + cwd.string() + "' && '" + ANGIOSYNTH_EXE + "' " + args + " 2>'" + err.string() + "' >/dev/null";
  const int status = std::system(cmd.c_str());
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace
