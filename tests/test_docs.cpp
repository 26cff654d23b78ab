// The docs stay true: each generated block of docs/ holds what the program prints now (rewrite
// them with scripts/docs.sh), and every command of the README's code blocks runs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "cli_run.hpp"
#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;

std::string slurpText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs a shell command in `dir` with the program on PATH as `angiosynth`; returns its stdout, or
// fails the test with its exit status.
std::string shellOutput(const std::string& command, const fs::path& dir) {
  const fs::path out = dir / "stdout.txt";
  const std::string full = "cd '" + dir.string() + "' && PATH='" + fs::path(ANGIOSYNTH_EXE).parent_path().string() + "':\"$PATH\" " + command +
                           " > '" + out.string() + "' 2> '" + (dir / "stderr.txt").string() + "'";
  const int status = std::system(full.c_str());
  EXPECT_EQ(status, 0) << command << "\n" << slurpText(dir / "stderr.txt");
  return slurpText(out);
}

class Docs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("angiosynth_docs_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(Docs, GeneratedBlocksHoldWhatTheProgramPrints) {
  // Blocks are found by plain search: libstdc++'s std::regex recurses once per character it
  // matches, and a block of a few hundred lines overflows the stack under the address sanitizer.
  const std::string open = "<!-- generated: ", close = "<!-- end generated -->";
  int blocks = 0;
  for (const auto& entry : fs::recursive_directory_iterator(angiosynth::test::sourceDir() / "docs")) {
    if (entry.path().extension() != ".md") continue;
    const std::string page = slurpText(entry.path());
    for (std::size_t at = page.find(open); at != std::string::npos; at = page.find(open, at + 1)) {
      const std::size_t args_end = page.find(" -->\n", at);
      ASSERT_NE(args_end, std::string::npos) << entry.path().filename() << ": a generated block's opening line has no ' -->'";
      const std::size_t body = args_end + 5, end = page.find(close, body);
      ASSERT_NE(end, std::string::npos) << entry.path().filename() << ": a generated block has no '" << close << "'";
      const std::string args = page.substr(at + open.size(), args_end - at - open.size()), held = page.substr(body, end - body);
      std::string want = shellOutput("angiosynth " + args, dir_);
      if (args != "methods" && args != "effects") {
        while (!want.empty() && want.back() == '\n') want.pop_back();
        want = "```text\n" + want + "\n```\n";
      }
      EXPECT_EQ(held, want) << entry.path().filename() << ": the block of `angiosynth " << args << "` is stale; run bash scripts/docs.sh";
      ++blocks;
    }
  }
  EXPECT_GE(blocks, 17);
}

// Every relative link of the README and the docs names a file that exists.
TEST_F(Docs, EveryRelativeLinkResolves) {
  const fs::path src = angiosynth::test::sourceDir();
  std::vector<fs::path> pages{src / "README.md"};
  for (const auto& entry : fs::recursive_directory_iterator(src / "docs"))
    if (entry.path().extension() == ".md") pages.push_back(entry.path());
  const std::regex link(R"(\]\(([^)#\s]+)(#[^)]*)?\))");
  int links = 0;
  for (const auto& page : pages) {
    const std::string text = slurpText(page);
    for (std::sregex_iterator it(text.begin(), text.end(), link), end; it != end; ++it) {
      const std::string target = (*it)[1];
      if (target.rfind("http", 0) == 0) continue;
      EXPECT_TRUE(fs::exists(page.parent_path() / target)) << page.filename() << " links to " << target << ", which does not exist";
      ++links;
    }
  }
  EXPECT_GE(links, 40);
}

// The README's commands, each code block's lines in order, in a directory laid out like the
// source tree (the installing and building scripts are what CI itself runs, so they are left out).
TEST_F(Docs, ReadmeCommandsRun) {
  const fs::path src = angiosynth::test::sourceDir();
  fs::create_directories(dir_ / "build");
  fs::create_symlink(ANGIOSYNTH_EXE, dir_ / "build/angiosynth");
  for (const char* d : {"examples", "demand_maps", "noise_profiles"}) fs::create_directory_symlink(src / d, dir_ / d);
  std::istringstream readme(slurpText(src / "README.md"));
  bool in_block = false;
  std::string command;
  int ran = 0;
  for (std::string line; std::getline(readme, line);) {
    if (line.rfind("```", 0) == 0) {
      in_block = !in_block && line == "```sh";
      continue;
    }
    if (!in_block) continue;
    // Continued lines join; a comment after two spaces is the README's, not the shell's.
    if (const auto hash = line.find("  #"); hash != std::string::npos) line.erase(hash);
    command += line;
    if (!command.empty() && command.back() == '\\') {
      command.pop_back();
      continue;
    }
    while (!command.empty() && command.back() == ' ') command.pop_back();
    if (!command.empty() && command.rfind("bash scripts/", 0) != 0) {
      shellOutput(command, dir_);
      ++ran;
    }
    command.clear();
  }
  EXPECT_GE(ran, 4);
  EXPECT_TRUE(fs::exists(dir_ / "out/scores.csv"));
}

}  // namespace

// The scoring page's worked example holds what its script prints now: each row of the table it
// prints is a row of docs/scoring.md (a table of older numbers once stayed after the scores moved).
TEST_F(Docs, ScoringWorkedExampleHoldsWhatItsScriptPrints) {
  const fs::path src = angiosynth::test::sourceDir();
  const std::string printed = shellOutput("ANGIOSYNTH='" + std::string(ANGIOSYNTH_EXE) + "' bash '" +
                                              (src / "examples/score_thresholds.sh").string() + "' '" + (dir_ / "work").string() + "'",
                                          dir_);
  const std::string page = slurpText(src / "docs/scoring.md");
  std::istringstream rows(printed);
  int checked = 0;
  for (std::string row; std::getline(rows, row);) {
    if (row.rfind("| ", 0) != 0) continue;
    EXPECT_NE(page.find(row + "\n"), std::string::npos) << "docs/scoring.md lacks the row\n" << row;
    ++checked;
  }
  EXPECT_EQ(checked, 4);  // the header and three thresholds
  EXPECT_TRUE(fs::exists(dir_ / "work/calibre.png"));
}
