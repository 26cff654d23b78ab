#include "dataset/manifest.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <openssl/evp.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <memory>

#include "core/error.hpp"
#include "files/output_guard.hpp"

namespace angiosynth {

namespace {

using DigestContext = std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)>;

std::string hexDigest(DigestContext& ctx) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  EVP_DigestFinal_ex(ctx.get(), md, &len);
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < len; ++i) out += hex[md[i] >> 4], out += hex[md[i] & 15];
  return out;
}

DigestContext newDigest() {
  DigestContext ctx(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr);
  return ctx;
}

}  // namespace

std::string sha256File(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), 0, "cannot be read");
  DigestContext ctx = newDigest();
  std::vector<char> buf(1 << 20);
  while (in) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    EVP_DigestUpdate(ctx.get(), buf.data(), static_cast<std::size_t>(in.gcount()));
  }
  return hexDigest(ctx);
}

std::string sha256Text(const std::string& text) {
  DigestContext ctx = newDigest();
  EVP_DigestUpdate(ctx.get(), text.data(), text.size());
  return hexDigest(ctx);
}

void appendManifestLine(const std::filesystem::path& part, const nlohmann::json& entry) {
  const std::string line = entry.dump() + "\n";
  const int fd = ::open(part.c_str(), O_RDWR | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(part.string(), 0, "cannot be opened for appending");
  bool ok = ::flock(fd, LOCK_EX) == 0;
  // A torn last line (a killed writer): cut back to the last complete line first.
  struct stat st {};
  if (ok && ::fstat(fd, &st) == 0 && st.st_size > 0) {
    char last = '\n';
    if (::pread(fd, &last, 1, st.st_size - 1) == 1 && last != '\n') {
      off_t keep = 0;
      std::vector<char> buf(1 << 16);
      for (off_t end = st.st_size; end > 0 && keep == 0;) {
        const off_t begin = std::max<off_t>(0, end - off_t(buf.size()));
        const ssize_t got = ::pread(fd, buf.data(), std::size_t(end - begin), begin);
        if (got <= 0) break;
        for (ssize_t i = got - 1; i >= 0; --i)
          if (buf[std::size_t(i)] == '\n') {
            keep = begin + i + 1;
            break;
          }
        end = begin;
      }
      ok = ::ftruncate(fd, keep) == 0;
    }
  }
  ok = ok && ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size()) && ::fsync(fd) == 0;
  ::flock(fd, LOCK_UN);
  ::close(fd);
  if (!ok) throw InputError(part.string(), 0, "could not be written (disk full?)");
}

std::string manifestEntryProblem(const nlohmann::json& j, std::int64_t samples) {
  if (!j.is_object()) return "not a JSON object";
  if (!j.contains("index") || !j["index"].is_number_integer()) return "index is missing or not a whole number";
  const auto index = j["index"].get<std::int64_t>();
  if (index < 0 || index >= samples) return "index " + std::to_string(index) + " is outside 0…" + std::to_string(samples - 1);
  if (!j.contains("status") || !j["status"].is_string()) return "status is missing or not a string";
  const auto status = j["status"].get<std::string>();
  if (j.contains("finished_unix") && !j["finished_unix"].is_number()) return "finished_unix is not a number";
  for (const char* key : {"id", "profile", "error", "part", "sample_sha256"})
    if (j.contains(key) && !j[key].is_string()) return std::string(key) + " is not a string";
  if (status != "ok" && status != "failed") return "status '" + status + "'; allowed: ok, failed";
  // A failed entry may still list files (a sample that failed late); they are checked the same way.
  if (status == "failed" && !j.contains("files")) return "";
  if (!j.contains("files") || !j["files"].is_array() || (status == "ok" && j["files"].empty()))
    return status == "ok" ? "files is missing or empty" : "files is not a list";
  for (const auto& f : j["files"]) {
    if (!f.is_object() || !f.contains("path") || !f["path"].is_string() || !f.contains("size") || !f["size"].is_number_unsigned() ||
        !f.contains("sha256") || !f["sha256"].is_string())
      return "a file needs path (string), size (whole number >= 0) and sha256 (string)";
    const auto path = f["path"].get<std::string>();
    const auto top = path.substr(0, path.find('/'));
    if (!isConfinedRelativePath(path) || (top != "imagesTr" && top != "labelsTr" && top != "groundtruth"))
      return "file path '" + path + "' leaves the dataset; allowed: relative paths under imagesTr/, labelsTr/, groundtruth/";
    const auto hash = f["sha256"].get<std::string>();
    if (hash.size() != 64 || hash.find_first_not_of("0123456789abcdef") != std::string::npos) return "sha256 of " + path + " is not 64 hex digits";
  }
  return "";
}

std::map<std::int64_t, nlohmann::json> readManifests(const std::filesystem::path& dir, std::int64_t samples, std::vector<std::string>* problems) {
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
    std::ifstream in(f, std::ios::binary);
    const std::string shown = std::filesystem::relative(f, dir, ec).string();
    int number = 0;
    for (std::string line; std::getline(in, line);) {
      ++number;
      const bool torn = in.eof();  // no newline after it: a write that was cut short
      const auto j = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
      std::string why = j.is_discarded() ? "not valid JSON" : manifestEntryProblem(j, samples);
      if (!why.empty()) {
        if (problems)
          problems->push_back(shown + ":" + std::to_string(number) + ": " + why +
                              (torn ? " (a torn last line; ignored, and cut off at the next append)" : "; line ignored"));
        continue;
      }
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
