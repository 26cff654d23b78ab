// Every test process works in a temporary directory of its own, removed when it ends: the tests
// leave nothing in /tmp (TMPDIR and gtest's TEST_TMPDIR point into it, for the programs they run too).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace {

class OwnTemporaryDirectory : public testing::Environment {
 public:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("angiosynth_tests_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    ::setenv("TMPDIR", dir_.c_str(), 1);
    ::setenv("TEST_TMPDIR", (dir_.string() + "/").c_str(), 1);
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }

 private:
  std::filesystem::path dir_;
};

[[maybe_unused]] testing::Environment* const kEnvironment = testing::AddGlobalTestEnvironment(new OwnTemporaryDirectory);

}  // namespace
