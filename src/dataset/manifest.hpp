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

// Hex SHA-256 of a file's bytes (OpenSSL).
std::string sha256File(const std::filesystem::path& file);

// Appends one line and flushes it to disk; a kill leaves at worst a torn last line, which
// readers skip.
void appendManifestLine(const std::filesystem::path& part, const nlohmann::json& entry);

// Every readable entry of every part and of manifest.jsonl; per index, the one that finished last.
std::map<std::int64_t, nlohmann::json> readManifests(const std::filesystem::path& dataset_dir);

// Whether every file of an entry exists with its recorded size and hash; if not, `why` says
// "missing <path>", "corrupt <path>" or "status <status>".
bool entryVerifies(const std::filesystem::path& dataset_dir, const nlohmann::json& entry, std::string* why = nullptr);

}  // namespace angiosynth
