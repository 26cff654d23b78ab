#include "dataset/manifest.hpp"

#include <fcntl.h>
#include <openssl/evp.h>
#include <unistd.h>

#include <fstream>
#include <memory>

#include "core/error.hpp"

namespace angiosynth {

std::string sha256File(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), 0, "cannot be read");
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr);
  std::vector<char> buf(1 << 20);
  while (in) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    EVP_DigestUpdate(ctx.get(), buf.data(), static_cast<std::size_t>(in.gcount()));
  }
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  EVP_DigestFinal_ex(ctx.get(), md, &len);
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < len; ++i) out += hex[md[i] >> 4], out += hex[md[i] & 15];
  return out;
}

void appendManifestLine(const std::filesystem::path& part, const nlohmann::json& entry) {
  const std::string line = entry.dump() + "\n";
  const int fd = ::open(part.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0) throw InputError(part.string(), 0, "cannot be opened for appending");
  const bool ok = ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size()) && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) throw InputError(part.string(), 0, "could not be written (disk full?)");
}

std::map<std::int64_t, nlohmann::json> readManifests(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  if (std::filesystem::exists(dir / "manifest.jsonl")) files.push_back(dir / "manifest.jsonl");
  std::error_code ec;
  std::vector<std::filesystem::path> parts;
  for (const auto& e : std::filesystem::directory_iterator(dir / "manifest", ec))
    if (e.path().extension() == ".jsonl") parts.push_back(e.path());
  std::sort(parts.begin(), parts.end());
  files.insert(files.end(), parts.begin(), parts.end());
  std::map<std::int64_t, nlohmann::json> out;
  for (const auto& f : files) {
    std::ifstream in(f);
    for (std::string line; std::getline(in, line);) {
      const auto j = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
      if (j.is_discarded() || !j.contains("index") || !j.contains("status")) continue;  // a torn last line
      const auto i = j["index"].get<std::int64_t>();
      auto it = out.find(i);
      // The entry that finished last wins, whichever part holds it.
      if (it == out.end() || j.value("finished_unix", 0.0) >= it->second.value("finished_unix", 0.0)) out[i] = j;
    }
  }
  return out;
}

bool entryVerifies(const std::filesystem::path& dir, const nlohmann::json& entry, std::string* why) {
  if (entry.value("status", "") != "ok") {
    if (why) *why = "status " + entry.value("status", "?");
    return false;
  }
  for (const auto& f : entry["files"]) {
    const auto path = dir / f["path"].get<std::string>();
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) {
      if (why) *why = "missing " + f["path"].get<std::string>();  // as `verify` reports it
      return false;
    }
    if (size != f["size"].get<std::uintmax_t>() || sha256File(path) != f["sha256"].get<std::string>()) {
      if (why) *why = "corrupt " + f["path"].get<std::string>();
      return false;
    }
  }
  return true;
}

}  // namespace angiosynth
