#pragma once
// Errors about the user's input carry the place they come from, so the CLI can print
// `file:line: what is wrong, what is allowed` and exit non-zero.
#include <stdexcept>
#include <string>

namespace angiosynth {

class InputError : public std::runtime_error {
 public:
  InputError(std::string file, int line, const std::string& message)
      : std::runtime_error(format(file, line, message)), file_(std::move(file)), line_(line) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  static std::string format(const std::string& file, int line, const std::string& message) {
    if (file.empty()) return message;
    return line > 0 ? file + ":" + std::to_string(line) + ": " + message : file + ": " + message;
  }
  std::string file_;
  int line_;
};

}  // namespace angiosynth
