#pragma once
// A dataset spec: a parameter file whose values may be distributions, plus a [dataset] table
// (name, id, sample count, base seed, image profile). Sample i's parameters and seed are a pure
// function of (base seed, i): any machine, shard or thread count resolves the same sample.
//
// A distribution replaces any value: {uniform = [a, b]}, {log_uniform = [a, b]},
// {normal = [mean, sd], min = …, max = …}, {integer = [a, b]}, {choice = [v, …], weights = […]}.
// Quantities with units ("0.3 mm") draw their number and keep their unit.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace toml {
inline namespace v3 {
class table;
}
}  // namespace toml

namespace angiosynth {

struct Profile;

// One value of a spec replaced, without editing the spec (a benchmark's rung, `dataset --set`):
// `key` dotted as in the spec ("tree.terminals", "dataset.profile"), or
// "profile.<effect type>.<parameter>" for that parameter of every such effect of the image
// profile ("profile.background" and "profile.vessel" for its intensities); `value` is TOML
// ("40", "\"0.3 mm\"", "{uniform = [1, 2]}").
struct SpecOverride {
  std::string key, value;
  std::string file;  // where the override was written, for errors
  int line = 0;
};

struct DatasetSpec {
  std::string file;    // the spec, for errors and provenance
  std::string text;    // its content, recorded in provenance.json
  std::string sha256;  // of its canonical form: comments, spacing and key order do not count
  std::string name;    // nnU-Net dataset name (letters, digits, '-', '_')
  int id = 1;          // nnU-Net dataset number, 1…999
  std::int64_t samples = 0;
  std::uint64_t seed = 0;
  std::string channel_name;  // dataset.json channel 0 (default from the profile: "CT" for cta)
  // labelsTr: "binary" (background 0, vessel 1: the mask) or "kind" (background 0, then one label
  // per kind in the order of `kinds`: the classes volume, numbered alike in every sample).
  std::string labels = "binary";
  std::vector<std::string> kinds;  // labels = "kind": default artery, vein
  int labels_line = 0;             // of `kinds`, else of `labels`, for errors about a sample's kinds
  // [image] label_policy of every sample (one for the whole dataset): labelsTr holds the policy's
  // label (a float partial volume for "soft"); "ignore" adds nnU-Net's ignore label. Unset:
  // "visible" with a degraded image, "binary" with the clean one.
  std::string label_policy = "binary";
  bool label_policy_by_default = false;  // unset in the spec: the sample files are given the default
  bool previews = false;                 // MIPs (PNG) of each sample's clean and degraded image in groundtruth/
  // The licence the dataset's author gives the generated data (an SPDX identifier or any text):
  // dataset.json and provenance.json name it.
  std::string licence = "CC0-1.0";
  bool record_host = false;             // provenance.json names the machines' host names (off: cores and memory only)
  std::vector<SpecOverride> overrides;  // applied to the text; part of sha256 and of every sample's hash
};

// The label values of labelsTr, as dataset.json and each sample's meta list them.
nlohmann::ordered_json labelValues(const DatasetSpec& spec);

DatasetSpec readDatasetSpec(const std::filesystem::path& file, const std::vector<SpecOverride>& overrides = {});

// "key=value" as `--set` takes it; throws InputError naming `file` and `line` when malformed.
SpecOverride parseSpecOverride(const std::string& assignment, const std::string& file, int line);

// The canonical form of a spec's text with its overrides (TOML re-serialised with sorted keys)
// and its SHA-256.
std::string canonicalSpecSha256(const std::string& spec_text, const std::string& file, const std::vector<SpecOverride>& overrides = {});
// Dotted keys whose values differ between two specs ("tree.terminals", "dataset.samples").
std::vector<std::string> changedSpecKeys(const std::string& old_text, const std::string& new_text,
                                         const std::vector<SpecOverride>& old_overrides = {}, const std::vector<SpecOverride>& new_overrides = {});
// The overrides as spec.json records them, and back.
nlohmann::json overridesJson(const std::vector<SpecOverride>& overrides);
std::vector<SpecOverride> overridesFromJson(const nlohmann::json& j, const std::string& file);

// The image profile of a sample: its profile with the spec's "profile." overrides applied.
Profile sampleProfile(const DatasetSpec& spec, const std::string& profile_ref);

// Reads every sample's draws and parameter file and every file they name (maps, masks,
// profiles), so a bad draw or a missing file fails before the first sample is written.
void checkSampleDraws(const DatasetSpec& spec, const std::vector<std::int64_t>& indices);

struct ResolvedSample {
  std::int64_t index = 0;
  std::string id;                            // <name>_<index, fixed width>
  std::uint64_t seed = 0;                    // the growth and degradation seed
  std::string profile;                       // the image channel's profile
  std::string toml;                          // the resolved parameter file (what `describe` prints)
  std::string sha256;                        // of toml and profile: what the sample's files depend on
  std::shared_ptr<const toml::table> table;  // the same, parsed
};

ResolvedSample resolveSample(const DatasetSpec& spec, std::int64_t index);
// The resolved parameter file for people: each number written with 17 digits (how toml++ and the
// draws write doubles, and what the sample's hash is of) in its shortest form that reads back
// to the same double (0.65000000000000002 → 0.65). The same sample when generated.
std::string readableParameters(const ResolvedSample& r);
// Fixed-width id of sample i: at least 4 digits, enough for every index of the dataset.
std::string sampleId(const DatasetSpec& spec, std::int64_t index);
std::string datasetDirName(const DatasetSpec& spec);  // DatasetNNN_Name

}  // namespace angiosynth
