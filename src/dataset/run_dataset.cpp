#include "dataset/run_dataset.hpp"

#include <toml++/toml.h>
#include <tbb/global_control.h>
#include <tbb/parallel_pipeline.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>

#include "angiosynth/version.hpp"
#include "core/error.hpp"
#include "core/memory.hpp"
#include "dataset/manifest.hpp"
#include "degrade/profile.hpp"
#include "core/interrupt_cleanup.hpp"
#include "files/atomic_file.hpp"
#include "files/output_guard.hpp"
#include "files/text_file.hpp"
#include "pipeline/generate_sample.hpp"
#include "pipeline/volume_outputs.hpp"
#include "raster/ground_truth.hpp"

namespace angiosynth {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

double nowUnix() { return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(); }

Json readJson(const fs::path& p) {
  std::ifstream in(p);
  if (!in) throw InputError(p.string(), 0, "missing; is this a dataset directory made by `angiosynth dataset`?");
  const Json j = Json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object())
    throw InputError(p.string(), 0, "is not a JSON object; the dataset directory is damaged (restore it, or generate again into a new directory)");
  return j;
}

// spec.json as written by runDataset; its fields checked before use.
Json readSpecRecord(const fs::path& dir) {
  Json j = readJson(dir / "spec.json");
  const auto bad = [&](const std::string& why) { throw InputError((dir / "spec.json").string(), 0, why + "; the dataset directory is damaged"); };
  if (!j.contains("samples") || !j["samples"].is_number_integer() || j["samples"].get<std::int64_t>() < 1 ||
      j["samples"].get<std::int64_t>() > 100000000)
    bad("samples must be a whole number in 1…10^8");
  if (!j.contains("name") || !j["name"].is_string() || j["name"].get<std::string>().empty()) bad("name must be a string");
  if (!j.contains("spec") || !j["spec"].is_string()) bad("spec must be the spec's text");
  return j;
}

void writeJsonAtomically(const fs::path& p, const Json& j) { writeFileAtomically(p, j.dump(2) + "\n"); }

Scenario scenarioOf(const DatasetSpec& spec, const ResolvedSample& r) {
  Scenario sc = readTomlParameters(*r.table, spec.file);
  sc.image.enabled = true;
  sc.image.formats = spec.previews ? std::vector<std::string>{"nifti", "png"} : std::vector<std::string>{"nifti"};
  sc.profiles = {r.profile};
  return sc;
}

// Memory of one sample in flight: the dense volumes, the largest profile, the demand map.
std::uint64_t sampleBytes(const DatasetSpec& spec, std::uint64_t limit) {
  const ResolvedSample r = resolveSample(spec, 0);
  const Scenario sc = scenarioOf(spec, r);
  const auto growth = sc.growth->prepare(limit);
  const DemandMap& map = growth->frame();
  const VolumeGrid g = imageGrid(map, sc.image, spec.file, 0);
  sampleProfile(spec, r.profile);
  return denseRasterBytes(g) + 4ULL * g.voxelCount() + 24ULL * g.voxelCount() + map.demand.size() * 16;
}

SampleRequest sampleRequest(const DatasetSpec& spec, const ResolvedSample& r, const Scenario& sc, std::uint64_t memory_limit) {
  SampleRequest req;
  req.scenario = &sc;
  req.seed = r.seed;
  req.sample = static_cast<std::uint64_t>(r.index);
  req.graph_id = r.id;
  req.memory_limit = memory_limit;
  req.record_timing = false;  // sample files depend on (spec, index) only
  if (spec.labels == "kind") req.class_kinds = spec.kinds;
  req.profiles = std::vector<Profile>{sampleProfile(spec, r.profile)};
  return req;
}

// The roles of imagesTr and labelsTr: the image of the profile, and as label the policy's label,
// the classes or the mask, of the warped image when the profile warps. Roles carry the profile's
// name (a profile file's stem), not its reference.
struct SampleRoles {
  std::string image, label;
};
SampleRoles sampleRoles(const DatasetSpec& spec, const ResolvedSample& r, const std::function<bool(const std::string&)>& made) {
  std::string suffix(1, '_');  // (appended: GCC 12 warns falsely, -Wrestrict, on "_" + string)
  suffix += sampleProfile(spec, r.profile).name;
  const auto own = [&](const std::string& role) { return made(role + suffix) ? role + suffix : role; };
  return {own("image"), own(spec.label_policy != "binary" ? "label" : spec.labels == "kind" ? "classes" : "mask")};
}

Json fileEntry(const fs::path& dir, const std::string& rel) {
  return Json{{"path", rel}, {"sha256", sha256File(dir / rel)}, {"size", fs::file_size(dir / rel)}};
}

// One sample: generate in a staging directory, then rename into the nnU-Net layout.
// Moves `fresh` to `target`, replacing a directory that may be there without deleting it before
// the new one is in place: the old one is first moved aside into `aside`.
void replaceDirectory(const fs::path& fresh, const fs::path& target, const fs::path& aside) {
  std::error_code ec;
  const bool had = fs::exists(target, ec);
  if (had) fs::rename(target, aside);
  try {
    fs::rename(fresh, target);
  } catch (...) {
    if (had) fs::rename(aside, target, ec);
    throw;
  }
  if (had) fs::remove_all(aside, ec);
}

Json generateOne(const DatasetSpec& spec, const fs::path& dir, const fs::path& process_staging, const ResolvedSample& r,
                 const DatasetRunOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  Json e{{"id", r.id}, {"index", r.index}, {"seed", r.seed}, {"profile", r.profile}, {"sample_sha256", r.sha256}};
  const fs::path staging = process_staging / r.id;
  try {
    fs::remove_all(staging);
    fs::create_directories(staging);
    const Scenario sc = scenarioOf(spec, r);
    const SampleRequest req = sampleRequest(spec, r, sc, opt.memory_limit);
    const SampleSummary sample = generateSample(req, staging);
    const SampleRoles roles = sampleRoles(spec, r, [&](const std::string& role) { return sample.wrote(role); });
    const auto written = [&](const std::string& role) { return staging / sample.file(role); };
    const fs::path label = written(roles.label), image = written(roles.image);
    const std::string image_rel = "imagesTr/" + r.id + "_0000.nii.gz", label_rel = "labelsTr/" + r.id + ".nii.gz";
    const std::string gt_rel = "groundtruth/" + r.id, json_rel = "groundtruth/" + r.id + ".json";
    Json meta{{"id", r.id},
              {"index", r.index},
              {"seed", r.seed},
              {"profile", r.profile},
              {"image", image_rel},
              {"label", label_rel},
              {"label_values", labelValues(spec)},
              {"parameters_toml", r.toml},
              {"sample", sample.sidecar}};
    writeTextFile(staging / "meta.json", [&](std::ostream& o) { o << meta.dump(2) << "\n"; });
    // Renames: ground truth first, the image last, then the manifest line. Each replaces an
    // earlier copy only once the new one is complete.
    fs::rename(staging / "meta.json", dir / json_rel);
    fs::rename(label, dir / label_rel);
    const fs::path image_tmp = dir / (image_rel + ".part");
    fs::rename(image, image_tmp);
    replaceDirectory(staging, dir / gt_rel, process_staging / (r.id + ".previous"));
    fs::rename(image_tmp, dir / image_rel);
    Json files = Json::array({fileEntry(dir, image_rel), fileEntry(dir, label_rel), fileEntry(dir, json_rel)});
    std::vector<std::string> gt;
    for (const auto& f : fs::recursive_directory_iterator(dir / gt_rel))
      if (f.is_regular_file()) gt.push_back(fs::relative(f.path(), dir).string());
    std::sort(gt.begin(), gt.end());
    for (const auto& f : gt) files.push_back(fileEntry(dir, f));
    e["status"] = "ok";
    e["files"] = files;
  } catch (const std::exception& ex) {
    std::error_code ec;
    fs::remove_all(staging, ec);
    e["status"] = "failed";
    e["error"] = ex.what();
  }
  e["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  e["finished_unix"] = nowUnix();
  return e;
}

// The machine a run used: its cores and memory, and its host name only when the spec asks for it
// (a host name can identify a person or an institution).
Json machine(bool record_host) {
  Json j{{"cores", std::thread::hardware_concurrency()}, {"memory_bytes", physicalMemoryBytes()}};
  if (record_host) {
    char host[256] = {0};
    ::gethostname(host, sizeof host - 1);
    j["hostname"] = host;
  }
  return j;
}

// How to cite what made a dataset, for dataset.json and provenance.json.
std::string citation() {
  return std::string("synthetic data generated with angiosynth ") + kVersion +
         ": cite angiosynth as its CITATION.cff gives, and the papers of the growth method and degradation profile used (docs/references.md)";
}

}  // namespace

DatasetSampleInMemory datasetSampleInMemory(const DatasetSpec& spec, std::int64_t index, std::uint64_t memory_limit,
                                            const std::function<bool()>& cancelled) {
  if (index < 0 || index >= spec.samples)
    throw InputError(spec.file, 0, "sample " + std::to_string(index) + " is not in the dataset; allowed: 0 … " + std::to_string(spec.samples - 1));
  DatasetSampleInMemory out;
  out.resolved = resolveSample(spec, index);
  const Scenario sc = scenarioOf(spec, out.resolved);
  SampleRequest req = sampleRequest(spec, out.resolved, sc, memory_limit);
  req.capture = &out.capture;
  req.write_files = false;
  req.cancelled = cancelled;
  out.summary = generateSample(req, {});
  // Without files the roles are those the volumes were kept under.
  const SampleRoles roles = sampleRoles(spec, out.resolved, [&](const std::string& role) {
    return std::any_of(out.capture.volumes.begin(), out.capture.volumes.end(), [&](const CapturedVolume& v) { return v.role == role; });
  });
  out.image_role = roles.image;
  out.label_role = roles.label;
  return out;
}

std::vector<std::int64_t> DatasetSelection::indices() const {
  std::vector<std::int64_t> out;
  for (std::int64_t i = begin; i < end; ++i)
    if (i % shards == shard) out.push_back(i);
  return out;
}

namespace {

// Refuses to mix specs or to overwrite silently: a directory made from another spec needs
// --resume --regenerate-changed; samples of this selection already made need --resume.
void checkExistingDataset(const DatasetSpec& spec, const fs::path& dir, const std::vector<std::int64_t>& todo, const DatasetRunOptions& opt,
                          bool& spec_changed) {
  spec_changed = false;
  std::error_code ec;
  if (!fs::exists(dir / "spec.json", ec)) return;
  const Json old = readSpecRecord(dir);
  const std::string old_text = old["spec"].get<std::string>();
  std::string old_hash;
  std::vector<SpecOverride> old_overrides;
  try {
    old_overrides = overridesFromJson(old.value("overrides", Json()), (dir / "spec.json").string());
    old_hash = canonicalSpecSha256(old_text, (dir / "spec.json").string(), old_overrides);
  } catch (const InputError&) {}
  spec_changed = old_hash != spec.sha256;
  if (spec_changed) {
    const auto keys = changedSpecKeys(old_text, spec.text, old_overrides, spec.overrides);
    std::string list;
    for (std::size_t i = 0; i < keys.size() && i < 12; ++i) list += (i ? ", " : "") + keys[i];
    if (keys.size() > 12) list += ", … (" + std::to_string(keys.size()) + " in all)";
    if (!(opt.resume && opt.regenerate_changed))
      throw InputError(spec.file, 0,
                       dir.string() + " was made from another version of this spec (changed: " + list +
                           "); generate into a new directory, or add --resume --regenerate-changed to "
                           "regenerate the samples the change affects and keep the others");
  }
  if (opt.resume) return;
  const auto done = readManifests(dir, spec.samples);
  std::int64_t made = 0;
  for (auto i : todo) made += done.count(i);
  if (made > 0)
    throw InputError(dir.string(), 0,
                     "already holds " + std::to_string(made) + " of the " + std::to_string(todo.size()) +
                         " samples this run would make; add --resume to keep the verified ones and "
                         "redo the rest, or choose another --out");
}

// This process's staging directory; staging left by killed processes of this host is removed.
fs::path processStaging(const fs::path& dir) {
  const fs::path root = dir / ".staging";
  fs::create_directories(root);
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(root, ec))
    if (stagingOwnerIsGone(e.path().filename().string())) fs::remove_all(e.path(), ec);
  const fs::path mine = root / stagingSuffix();
  fs::remove_all(mine, ec);
  fs::create_directories(mine);
  registerStaging(mine);
  return mine;
}

}  // namespace

DatasetRunReport runDataset(const DatasetSpec& spec, const fs::path& out_parent, const DatasetSelection& sel, const DatasetRunOptions& opt) {
  DatasetRunReport rep;
  std::vector<std::int64_t> todo = sel.indices();
  // Every sample's draws, parameters and files, then sample 0's maps and profile: input errors
  // surface before anything is written.
  checkSampleDraws(spec, todo);
  const std::uint64_t per_sample = std::max<std::uint64_t>(1, sampleBytes(spec, opt.memory_limit));
  checkOutputPath(out_parent, {spec.file}, "--out");
  const fs::path dir = out_parent / datasetDirName(spec);
  rep.dir = dir;
  bool spec_changed = false;
  checkExistingDataset(spec, dir, todo, opt, spec_changed);
  for (const char* sub : {"imagesTr", "labelsTr", "groundtruth", "manifest"}) fs::create_directories(dir / sub);
  const fs::path staging = processStaging(dir);
  // Files of a run that was killed while writing them (SIGKILL cannot be caught).
  for (const fs::path& d : {dir, dir / "manifest"}) removeAbandonedTemporaries(d);
  // The same content from every process, so concurrent shards may all write it.
  Json spec_record{{"name", spec.name},          {"id", spec.id}, {"samples", spec.samples}, {"seed", spec.seed}, {"channel_name", spec.channel_name},
                   {"labels", labelValues(spec)}};
  if (spec.label_policy != "binary") spec_record["label_policy"] = spec.label_policy;  // binary datasets as before
  spec_record["licence"] = spec.licence;
  if (spec.record_host) spec_record["record_host"] = true;
  spec_record["spec_file"] = spec.file;
  spec_record["spec_sha256"] = spec.sha256;
  spec_record["spec"] = spec.text;
  if (!spec.overrides.empty()) spec_record["overrides"] = overridesJson(spec.overrides);  // datasets without any as before
  writeJsonAtomically(dir / "spec.json", spec_record);
  writeJsonAtomically(dir / "manifest" / (sel.part + ".run.json"), Json{{"tool", {{"name", "angiosynth"}, {"version", kVersion}}},
                                                                        {"command_line", opt.command_line},
                                                                        {"part", sel.part},
                                                                        {"machine", machine(spec.record_host)},
                                                                        {"started_unix", nowUnix()}});
  if (opt.resume) {
    const auto done = readManifests(dir, spec.samples);
    std::vector<std::int64_t> left;
    for (auto i : todo) {
      const auto it = done.find(i);
      // Made from the same resolved parameters (entries of older versions carry no hash: only
      // an unchanged spec vouches for them), and every file intact.
      const bool same =
          it != done.end() && (it->second.contains("sample_sha256") ? it->second["sample_sha256"] == resolveSample(spec, i).sha256 : !spec_changed);
      if (same && entryVerifies(dir, it->second))
        ++rep.skipped;
      else
        left.push_back(i);
    }
    todo = left;
  }
  // Samples in flight: one per core, fewer if memory does not allow.
  const auto cores = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);  // honours --threads
  const std::uint64_t wanted = opt.samples_in_flight > 0 ? std::uint64_t(opt.samples_in_flight) : cores;
  rep.in_flight = static_cast<int>(std::max<std::uint64_t>(1, std::min<std::uint64_t>(wanted, opt.memory_limit / per_sample)));
  const fs::path part = dir / "manifest" / (sel.part + ".jsonl");
  std::mutex m;
  std::size_t next = 0;
  std::int64_t finished = 0;
  const std::int64_t total = static_cast<std::int64_t>(todo.size());
  tbb::parallel_pipeline(static_cast<std::size_t>(rep.in_flight),
                         tbb::make_filter<void, std::int64_t>(tbb::filter_mode::serial_in_order, [&](tbb::flow_control& fc) -> std::int64_t {
                           if (next == todo.size()) {
                             fc.stop();
                             return 0;
                           }
                           return todo[next++];
                         }) & tbb::make_filter<std::int64_t, void>(tbb::filter_mode::parallel, [&](std::int64_t i) {
                           const ResolvedSample r = resolveSample(spec, i);
                           Json e = generateOne(spec, dir, staging, r, opt);
                           e["part"] = sel.part;
                           std::lock_guard<std::mutex> lock(m);
                           appendManifestLine(part, e);
                           ++finished;
                           if (e["status"] == "ok")
                             ++rep.generated;
                           else
                             ++rep.failed;
                           if (opt.on_sample) opt.on_sample(e, finished, total);
                         }));
  // Only this process's own staging: other shards may be writing theirs.
  std::error_code ec;
  fs::remove_all(staging, ec);
  unregisterStaging(staging);
  fs::remove(dir / ".staging", ec);  // if no other shard's staging is in it (else ENOTEMPTY)
  return rep;
}

namespace {

DatasetCheck checkDataset(const fs::path& dir, bool rehash, std::map<std::int64_t, Json>& entries, Json& info) {
  if (!fs::is_directory(dir)) throw InputError(dir.string(), 0, "no such dataset directory");
  info = readSpecRecord(dir);
  DatasetCheck c;
  c.samples = info["samples"].get<std::int64_t>();
  entries = readManifests(dir, c.samples, &c.warnings);
  DatasetSpec naming;
  naming.name = info["name"];
  naming.samples = c.samples;
  for (std::int64_t i = 0; i < c.samples; ++i) {
    const auto it = entries.find(i);
    const std::string id = sampleId(naming, i);
    if (it == entries.end()) {
      c.problems.push_back("missing " + id);
      continue;
    }
    if (it->second["status"] != "ok") {
      c.problems.push_back("failed " + id + ": " + it->second.value("error", "?"));
      continue;
    }
    std::string why;  // "missing <path>" or "corrupt <path>"
    if (rehash && !entryVerifies(dir, it->second, &why)) {
      const std::string kind = why.substr(0, why.find(' ')), path = why.substr(why.find(' ') + 1);
      c.problems.push_back((kind == "missing" ? "missing file of " : "corrupt ") + id + ": " + path);
      continue;
    }
    ++c.ok;
  }
  return c;
}

}  // namespace

DatasetCheck finalizeDataset(const fs::path& dir) {
  std::map<std::int64_t, Json> entries;
  Json info;
  DatasetCheck c = checkDataset(dir, /*rehash=*/false, entries, info);
  // manifest.jsonl: every sample's last entry, in index order.
  std::string manifest;
  for (const auto& [i, e] : entries)
    if (i < c.samples) manifest += e.dump() + "\n";
  writeFileAtomically(dir / "manifest.jsonl", manifest);
  // nnU-Net's dataset.json; "CT" makes nnU-Net use its CT (global percentile) normalisation.
  std::string channel = info.contains("channel_name") && info["channel_name"].is_string() ? info["channel_name"].get<std::string>() : "";
  if (channel.empty()) {
    std::set<std::string> profiles;
    for (const auto& [i, e] : entries) profiles.insert(e.value("profile", ""));
    channel = profiles.size() == 1 && *profiles.begin() == "cta" ? "CT" : (profiles.size() == 1 ? *profiles.begin() : "image");
  }
  // Datasets of older versions record no labels: they are binary.
  const Json labels = info.contains("labels") && info["labels"].is_object() ? info["labels"] : Json{{"background", 0}, {"vessel", 1}};
  std::int64_t training = 0;
  for (const auto& [i, e] : entries) training += i < c.samples && e["status"] == "ok";
  Json dataset_json{{"channel_names", {{"0", channel}}},
                    {"labels", labels},
                    {"numTraining", training},
                    {"file_ending", ".nii.gz"},
                    {"name", info["name"]},
                    {"description", "synthetic vascular trees with exact ground truth (angiosynth)"},
                    {"licence", info.value("licence", std::string("not recorded (made by an earlier version)"))},
                    {"reference", citation()},
                    {"release", kVersion}};
  // A non-binary label policy is named (nnU-Net reads the ignore label from "labels"; "soft"
  // labelsTr hold the partial volume as float, for trainers with soft targets).
  if (info.contains("label_policy")) dataset_json["label_policy"] = info["label_policy"];
  writeJsonAtomically(dir / "dataset.json", dataset_json);
  Json runs = Json::array();
  std::vector<fs::path> run_files;
  std::error_code ec;
  for (const auto& f : fs::directory_iterator(dir / "manifest", ec))
    if (f.path().string().ends_with(".run.json")) run_files.push_back(f.path());
  std::sort(run_files.begin(), run_files.end());
  for (const auto& f : run_files) {
    std::ifstream in(f);
    const Json run = Json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (run.is_discarded())
      c.warnings.push_back(fs::relative(f, dir).string() + ": not valid JSON; left out of provenance.json");
    else
      runs.push_back(run);
  }
  writeJsonAtomically(dir / "provenance.json", Json{{"tool", {{"name", "angiosynth"}, {"version", kVersion}}},
                                                    {"spec_file", info["spec_file"]},
                                                    {"spec", info["spec"]},
                                                    {"overrides", info.value("overrides", Json::array())},
                                                    {"seed", info["seed"]},
                                                    {"samples", c.samples},
                                                    {"licence", info.value("licence", std::string("not recorded (made by an earlier version)"))},
                                                    {"citation", citation()},
                                                    {"finalized_on", machine(info.value("record_host", false))},
                                                    {"finalized_unix", nowUnix()},
                                                    {"runs", runs}});
  return c;
}

DatasetCheck verifyDataset(const fs::path& dir) {
  std::map<std::int64_t, Json> entries;
  Json info;
  DatasetCheck c = checkDataset(dir, /*rehash=*/true, entries, info);
  // Images or labels nobody recorded (a sample killed before its manifest line).
  std::set<std::string> known;
  for (const auto& [i, e] : entries)
    for (const auto& file : e.value("files", Json::array())) known.insert(file["path"].get<std::string>());
  for (const char* sub : {"imagesTr", "labelsTr"}) {
    if (!fs::is_directory(dir / sub)) {
      c.problems.push_back(std::string("missing directory ") + sub + "/");
      continue;
    }
    for (const auto& f : fs::directory_iterator(dir / sub)) {
      const std::string rel = std::string(sub) + "/" + f.path().filename().string();
      if (!known.count(rel)) c.problems.push_back("stray " + rel);
    }
  }
  return c;
}

}  // namespace angiosynth
