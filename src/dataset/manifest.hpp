#pragma once
// The dataset manifest: one JSON line per finished sample (id, index, seed, every file with its
// sha256 and size, status, time). Each process appends to its own part under manifest/, so
// shards never write the same file; `finalize` merges the parts into manifest.jsonl.
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace angiosynth {

// Hex SHA-256 of a file's bytes, or of a string (OpenSSL).
std::string sha256File(const std::filesystem::path& file);
std::string sha256Text(const std::string& text);

// Appends one line and flushes it to disk, under an exclusive lock (flock), in one write. A kill
// or a full disk leaves at worst a torn last line: readers skip it, and the next append first cuts
// the file back to its last complete line, so an entry is never glued onto a fragment.
void appendManifestLine(const std::filesystem::path& part, const nlohmann::json& entry);

// Why an entry is unusable ("" if it is fine): index a whole number in [0, samples), status "ok"
// or "failed", and for "ok" a non-empty files list of {path, size, sha256} whose paths are
// relative, free of "..", and under imagesTr/, labelsTr/ or groundtruth/.
std::string manifestEntryProblem(const nlohmann::json& entry, std::int64_t samples);

// Every valid entry of every part and of manifest.jsonl; per index, the one that finished last.
// Invalid lines are skipped (one bad line blocks nothing) and described in `problems` as
// "manifest/<part>.jsonl:<line>: <why>".
std::map<std::int64_t, nlohmann::json> readManifests(const std::filesystem::path& dataset_dir, std::int64_t samples = INT64_MAX,
                                                     std::vector<std::string>* problems = nullptr);

// Whether every file of a valid entry exists with its recorded size and hash; if not, `why` says
// "missing <path>", "corrupt <path>" or "status <status>".
bool entryVerifies(const std::filesystem::path& dataset_dir, const nlohmann::json& entry, std::string* why = nullptr);

}  // namespace angiosynth
