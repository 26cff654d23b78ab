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
#include "io/map_files.hpp"
#include "io/text_file.hpp"
#include "pipeline/generate_sample.hpp"
#include "pipeline/volume_outputs.hpp"
#include "raster/ground_truth.hpp"

namespace angiosynth {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

double nowUnix() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

Json readJson(const fs::path& p) {
  std::ifstream in(p);
  if (!in) throw InputError(p.string(), 0, "missing; is this a dataset directory made by `angiosynth dataset`?");
  return Json::parse(in);
}

void writeJsonAtomically(const fs::path& p, const Json& j) {
  const fs::path tmp = p.string() + ".tmp" + std::to_string(::getpid());
  writeTextFile(tmp, [&](std::ostream& o) { o << j.dump(2) << "\n"; });
  fs::rename(tmp, p);
}

Scenario scenarioOf(const DatasetSpec& spec, const ResolvedSample& r) {
  Scenario sc = readTomlParameters(*r.table, spec.file);
  sc.image.enabled = true;
  sc.image.formats = {"nifti"};
  sc.profiles = {r.profile};
  return sc;
}

// Memory of one sample in flight: the dense volumes, the largest profile, the demand map.
std::uint64_t sampleBytes(const DatasetSpec& spec, std::uint64_t limit) {
  const ResolvedSample r = resolveSample(spec, 0);
  const Scenario sc = scenarioOf(spec, r);
  const DemandMap map = loadDomain(sc, limit);
  const VolumeGrid g = imageGrid(map, sc.image);
  loadProfile(r.profile, spec.file, 0);
  return denseRasterBytes(g) + 4ULL * g.voxelCount() + 24ULL * g.voxelCount() + map.demand.size() * 16;
}

Json fileEntry(const fs::path& dir, const std::string& rel) {
  return Json{{"path", rel}, {"sha256", sha256File(dir / rel)}, {"size", fs::file_size(dir / rel)}};
}

// One sample: generate in a staging directory, then rename into the nnU-Net layout.
Json generateOne(const DatasetSpec& spec, const fs::path& dir, const ResolvedSample& r, const DatasetRunOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  Json e{{"id", r.id}, {"index", r.index}, {"seed", r.seed}, {"profile", r.profile}};
  const fs::path staging = dir / ".staging" / (r.id + "." + std::to_string(::getpid()));
  try {
    // Leftovers of this sample from a killed run (any process: a sample belongs to one shard).
    for (const auto& f : fs::directory_iterator(dir / ".staging"))
      if (f.path().filename().string().rfind(r.id + ".", 0) == 0) fs::remove_all(f.path());
    fs::create_directories(staging);
    const Scenario sc = scenarioOf(spec, r);
    SampleRequest req;
    req.scenario = &sc;
    req.seed = r.seed;
    req.sample = static_cast<std::uint64_t>(r.index);
    req.graph_id = r.id;
    req.memory_limit = opt.memory_limit;
    req.record_timing = false;  // sample files depend on (spec, index) only
    const Json sample = generateSample(req, staging);
    const std::string suffix = "_" + r.profile;
    const fs::path label = fs::exists(staging / ("mask" + suffix + ".nii.gz")) ? staging / ("mask" + suffix + ".nii.gz")
                                                                             : staging / "mask.nii.gz";
    const std::string image_rel = "imagesTr/" + r.id + "_0000.nii.gz", label_rel = "labelsTr/" + r.id + ".nii.gz";
    const std::string gt_rel = "groundtruth/" + r.id, json_rel = "groundtruth/" + r.id + ".json";
    Json meta{{"id", r.id},
              {"index", r.index},
              {"seed", r.seed},
              {"profile", r.profile},
              {"image", image_rel},
              {"label", label_rel},
              {"label_values", {{"background", 0}, {"vessel", 1}}},
              {"parameters_toml", r.toml},
              {"sample", sample}};
    writeTextFile(staging / "meta.json", [&](std::ostream& o) { o << meta.dump(2) << "\n"; });
    // Renames: ground truth first, the image last, then the manifest line.
    fs::remove_all(dir / gt_rel);
    fs::rename(staging / "meta.json", dir / json_rel);
    fs::rename(label, dir / label_rel);
    fs::path image = staging / ("image" + suffix + ".nii.gz");
    if (!fs::exists(image)) image = staging / "image.nii.gz";
    const fs::path image_tmp = dir / (image_rel + ".part");
    fs::rename(image, image_tmp);
    fs::rename(staging, dir / gt_rel);
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

Json machine() {
  char host[256] = {0};
  ::gethostname(host, sizeof host - 1);
  return Json{{"hostname", host},
              {"cores", std::thread::hardware_concurrency()},
              {"memory_bytes", physicalMemoryBytes()}};
}

}  // namespace

std::vector<std::int64_t> DatasetSelection::indices() const {
  std::vector<std::int64_t> out;
  for (std::int64_t i = begin; i < end; ++i)
    if (i % shards == shard) out.push_back(i);
  return out;
}

DatasetRunReport runDataset(const DatasetSpec& spec, const fs::path& out_parent, const DatasetSelection& sel,
                            const DatasetRunOptions& opt) {
  DatasetRunReport rep;
  // Reads sample 0's maps and profile: input errors surface before anything is written.
  const std::uint64_t per_sample = std::max<std::uint64_t>(1, sampleBytes(spec, opt.memory_limit));
  const fs::path dir = out_parent / datasetDirName(spec);
  rep.dir = dir;
  for (const char* sub : {"imagesTr", "labelsTr", "groundtruth", "manifest", ".staging"}) fs::create_directories(dir / sub);
  // The same content from every process, so concurrent shards may all write it.
  writeJsonAtomically(dir / "spec.json", Json{{"name", spec.name},
                                              {"id", spec.id},
                                              {"samples", spec.samples},
                                              {"seed", spec.seed},
                                              {"channel_name", spec.channel_name},
                                              {"spec_file", spec.file},
                                              {"spec", spec.text}});
  writeJsonAtomically(dir / "manifest" / (sel.part + ".run.json"),
                      Json{{"tool", {{"name", "angiosynth"}, {"version", kVersion}}},
                           {"command_line", opt.command_line},
                           {"part", sel.part},
                           {"machine", machine()},
                           {"started_unix", nowUnix()}});
  std::vector<std::int64_t> todo = sel.indices();
  if (opt.resume) {
    const auto done = readManifests(dir);
    std::vector<std::int64_t> left;
    for (auto i : todo) {
      const auto it = done.find(i);
      if (it != done.end() && entryVerifies(dir, it->second)) ++rep.skipped;
      else left.push_back(i);
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
  tbb::parallel_pipeline(
      static_cast<std::size_t>(rep.in_flight),
      tbb::make_filter<void, std::int64_t>(tbb::filter_mode::serial_in_order,
                                           [&](tbb::flow_control& fc) -> std::int64_t {
                                             if (next == todo.size()) {
                                               fc.stop();
                                               return 0;
                                             }
                                             return todo[next++];
                                           }) &
          tbb::make_filter<std::int64_t, void>(tbb::filter_mode::parallel, [&](std::int64_t i) {
            const ResolvedSample r = resolveSample(spec, i);
            Json e = generateOne(spec, dir, r, opt);
            e["part"] = sel.part;
            std::lock_guard<std::mutex> lock(m);
            appendManifestLine(part, e);
            ++finished;
            if (e["status"] == "ok") ++rep.generated;
            else ++rep.failed;
            if (opt.on_sample) opt.on_sample(e, finished, total);
          }));
  std::error_code ec;
  fs::remove(dir / ".staging", ec);  // only if empty: other processes may be staging
  return rep;
}

namespace {

DatasetCheck checkDataset(const fs::path& dir, bool rehash, std::map<std::int64_t, Json>& entries, Json& info) {
  info = readJson(dir / "spec.json");
  entries = readManifests(dir);
  DatasetCheck c;
  c.samples = info["samples"].get<std::int64_t>();
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
  const fs::path tmp = dir / ("manifest.jsonl.tmp" + std::to_string(::getpid()));
  writeTextFile(tmp, [&](std::ostream& o) {
    for (const auto& [i, e] : entries)
      if (i < c.samples) o << e.dump() << "\n";
  });
  fs::rename(tmp, dir / "manifest.jsonl");
  // nnU-Net's dataset.json; "CT" makes nnU-Net use its CT (global percentile) normalisation.
  std::string channel = info.value("channel_name", "");
  if (channel.empty()) {
    std::set<std::string> profiles;
    for (const auto& [i, e] : entries) profiles.insert(e.value("profile", ""));
    channel = profiles.size() == 1 && *profiles.begin() == "cta" ? "CT" : (profiles.size() == 1 ? *profiles.begin() : "image");
  }
  std::int64_t training = 0;
  for (const auto& [i, e] : entries) training += i < c.samples && e["status"] == "ok";
  writeJsonAtomically(dir / "dataset.json",
                      Json{{"channel_names", {{"0", channel}}},
                           {"labels", {{"background", 0}, {"vessel", 1}}},
                           {"numTraining", training},
                           {"file_ending", ".nii.gz"},
                           {"name", info["name"]},
                           {"description", "synthetic vascular trees with exact ground truth (angiosynth)"},
                           {"licence", "generated data; see provenance.json"},
                           {"release", kVersion}});
  Json runs = Json::array();
  std::vector<fs::path> run_files;
  for (const auto& f : fs::directory_iterator(dir / "manifest"))
    if (f.path().string().size() > 9 && f.path().string().ends_with(".run.json")) run_files.push_back(f.path());
  std::sort(run_files.begin(), run_files.end());
  for (const auto& f : run_files) runs.push_back(readJson(f));
  writeJsonAtomically(dir / "provenance.json", Json{{"tool", {{"name", "angiosynth"}, {"version", kVersion}}},
                                                    {"spec_file", info["spec_file"]},
                                                    {"spec", info["spec"]},
                                                    {"seed", info["seed"]},
                                                    {"samples", c.samples},
                                                    {"finalized_on", machine()},
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
  for (const char* sub : {"imagesTr", "labelsTr"})
    for (const auto& f : fs::directory_iterator(dir / sub)) {
      const std::string rel = std::string(sub) + "/" + f.path().filename().string();
      if (!known.count(rel)) c.problems.push_back("stray " + rel);
    }
  return c;
}

}  // namespace angiosynth
