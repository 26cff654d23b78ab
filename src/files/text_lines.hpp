#pragma once
// Line-oriented reading shared by VascuSynth's text formats: CRLF or LF, numbered lines,
// strict number parsing with errors that name file and line.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace angiosynth {

struct TextLine {
  int number;
  std::string text;  // without line ending, trimmed
};

// Non-blank lines of a file ('#' starts a comment); throws InputError if it cannot be read.
std::vector<TextLine> readTextLines(const std::filesystem::path& file, const std::string& what);
std::vector<std::string> splitWords(const std::string& s);
std::string trimmed(const std::string& s);
// Strict conversions; throw InputError(file, line, "<what>: '<word>' is not ..., <allowed>").
double parseNumber(const std::string& word, const std::string& file, int line, const std::string& what);
std::int64_t parseInteger(const std::string& word, const std::string& file, int line, const std::string& what);

}  // namespace angiosynth
