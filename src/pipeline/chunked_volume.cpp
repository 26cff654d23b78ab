#include "pipeline/chunked_volume.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>

#include "core/error.hpp"
#include "core/memory.hpp"
#include "files/atomic_file.hpp"
#include "files/output_guard.hpp"
#include "pipeline/volume_files.hpp"
#include "raster/ground_truth.hpp"

namespace angiosynth {
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

// How a channel's coarser levels are made from the finer one.
enum class Reduce { Mean, Max, Mode, ImageOfFraction };

struct ChannelSpec {
  const char* group;  // the multiscale group's path in the store ("" for the image at the root)
  const char* name;
  Reduce reduce;
  bool label;
  const char* meaning;
};

// Level-0 order: what rasterizeChunks hands to the writers.
constexpr ChannelSpec kChannels[] = {
    {"", "image", Reduce::ImageOfFraction, false, "the image: background + fraction x (vessel - background), as [image] dtype"},
    {"fraction", "fraction", Reduce::Mean, false, "fraction of each voxel inside the vessels, [0, 1]"},
    {"radius", "radius", Reduce::Max, false, "vessel radius (mm) on centreline voxels, else 0"},
    {"labels/mask", "mask", Reduce::Max, true, "vessel mask: fraction >= 0.5 and every voxel a centreline crosses"},
    {"labels/centerline", "centerline", Reduce::Max, true, "centreline voxels"},
    {"labels/instances", "instances", Reduce::Mode, true, "segment id (the id of its distal node in nodes.csv) on mask voxels"},
    {"labels/classes", "classes", Reduce::Mode, true, "vessel kind on mask voxels: 1 artery, 2 vein, further kinds on"},
};
constexpr int kChannelCount = int(std::size(kChannels));

VoxelType imageType(const std::string& dtype) {
  if (dtype == "uint8") return VoxelType::UInt8;
  if (dtype == "uint16") return VoxelType::UInt16;
  if (dtype == "int16") return VoxelType::Int16;
  return VoxelType::Float32;
}

VoxelType channelType(int c, const ChunkedVolumeOptions& opt) {
  switch (c) {
    case 0: return imageType(opt.dtype);
    case 1:
    case 2: return VoxelType::Float32;
    case 5: return VoxelType::UInt32;
    default: return VoxelType::UInt8;
  }
}

// The image's value where there is no vessel, as the typed image stores it (makeTypedImage's rule).
double typedBackground(const ChunkedVolumeOptions& opt) {
  Volume<float> one(VolumeGrid{{1, 1, 1}, {}, {1, 1, 1}});
  TypedImage t;
  makeTypedImage(t, one, opt.background, opt.vessel - opt.background, opt.dtype, "");
  switch (t.view.type) {
    case VoxelType::UInt8: return t.u8.data[0];
    case VoxelType::UInt16: return t.u16.data[0];
    case VoxelType::Int16: return t.s16.data[0];
    default: return t.f32.data[0];
  }
}

std::array<std::int64_t, 3> levelShape(const VolumeGrid& g, int level) {  // z, y, x
  std::array<std::int64_t, 3> s{g.dims[2], g.dims[1], g.dims[0]};
  for (int l = 0; l < level; ++l)
    for (auto& n : s) n = (n + 1) / 2;
  return s;
}

ZarrArray arrayOf(const fs::path& store, const ChunkedVolumeOptions& opt, int channel, int level, double image_fill) {
  ZarrArray a;
  a.dir = store / kChannels[channel].group / std::to_string(level);
  a.shape = levelShape(opt.grid, level);
  a.chunks = {opt.chunk, opt.chunk, opt.chunk};
  a.type = channelType(channel, opt);
  a.fill = channel == 0 ? image_fill : 0;
  a.codec = opt.codec;
  a.level = opt.codec_level;
  return a;
}

// Level-0 chunks in x-fastest order; task i takes [N·i/n, N·(i+1)/n).
struct ChunkLayout {
  std::array<std::int64_t, 3> count{};  // x, y, z
  std::int64_t total = 0;
  std::int64_t chunk = 0;
  explicit ChunkLayout(const ChunkedVolumeOptions& opt) : chunk(opt.chunk) {
    for (int a = 0; a < 3; ++a) count[a] = (opt.grid.dims[a] + chunk - 1) / chunk;
    total = count[0] * count[1] * count[2];
  }
  std::int64_t begin(ChunkTask t) const { return total * t.index / t.count; }
  std::int64_t end(ChunkTask t) const { return total * (t.index + 1) / t.count; }
  std::array<std::int64_t, 3> coords(std::int64_t id) const { return {id % count[0], (id / count[0]) % count[1], id / (count[0] * count[1])}; }
  VoxelWindow window(std::int64_t id, const VolumeGrid& g) const {
    const auto c = coords(id);
    VoxelWindow w;
    for (int a = 0; a < 3; ++a) {
      w.lo[a] = c[a] * chunk;
      w.hi[a] = std::min<std::int64_t>(w.lo[a] + chunk, g.dims[a]);
    }
    return w;
  }
};

fs::path recordDir(const fs::path& store) { return store / ".angiosynth"; }
fs::path progressFile(const fs::path& store, ChunkTask t) {
  return recordDir(store) / ("level0-task-" + std::to_string(t.index) + "-of-" + std::to_string(t.count));
}
fs::path levelDoneFile(const fs::path& store, int level) { return recordDir(store) / ("level" + std::to_string(level) + "-done"); }

std::int64_t readCount(const fs::path& file) {
  std::ifstream in(file);
  std::int64_t n = 0;
  if (!(in >> n) || n < 0) return 0;
  return n;
}

// The segments that can reach each chunk of [first, last), in compressed rows (chunk − first):
// those whose box, grown by the radius and half a voxel, meets the chunk. Ascending in each row.
struct ChunkSegments {
  std::vector<std::int64_t> start;  // row offsets, size rows + 1
  std::vector<std::int32_t> segments;
  std::span<const std::int32_t> of(std::int64_t row) const {
    return {segments.data() + start[std::size_t(row)], std::size_t(start[std::size_t(row) + 1] - start[std::size_t(row)])};
  }
};

template <class F>
void forEachChunkReached(const VascularTree& t, const VolumeGrid& g, const ChunkLayout& layout, std::int32_t s, F&& f) {
  const Vec3 a = t.position[t.parent[s]], b = t.position[s];
  const double r = t.maxRadius(s);
  std::int64_t lo[3], hi[3];
  for (int ax = 0; ax < 3; ++ax) {
    const double ia = (a[ax] - g.origin_mm[ax]) / g.spacing_mm[ax], ib = (b[ax] - g.origin_mm[ax]) / g.spacing_mm[ax];
    const double rr = r / g.spacing_mm[ax] + 0.5 + 1e-6;
    const double x_lo = std::max(0.0, std::floor(std::min(ia, ib) - rr));
    const double x_hi = std::min(double(g.dims[ax] - 1), std::ceil(std::max(ia, ib) + rr));
    if (!(x_hi >= x_lo)) return;
    lo[ax] = std::int64_t(x_lo) / layout.chunk;
    hi[ax] = std::int64_t(x_hi) / layout.chunk;
  }
  for (std::int64_t k = lo[2]; k <= hi[2]; ++k)
    for (std::int64_t j = lo[1]; j <= hi[1]; ++j)
      for (std::int64_t i = lo[0]; i <= hi[0]; ++i) f(i + layout.count[0] * (j + layout.count[1] * k));
}

ChunkSegments segmentsOfChunks(const VascularTree& t, const VolumeGrid& g, const ChunkLayout& layout, std::int64_t first, std::int64_t last,
                               std::uint64_t memory_limit, const fs::path& store) {
  ChunkSegments out;
  out.start.assign(std::size_t(last - first + 1), 0);
  std::uint64_t pairs = 0;
  for (std::int32_t s = 1; s < t.nodeCount(); ++s) {
    if (t.isRoot(s)) continue;
    forEachChunkReached(t, g, layout, s, [&](std::int64_t c) {
      if (c >= first && c < last) ++out.start[std::size_t(c - first + 1)], ++pairs;
    });
  }
  if (pairs * sizeof(std::int32_t) > memory_limit)
    throw InputError(store.string(), 0,
                     "the chunks' segment lists need " + formatBytes(pairs * sizeof(std::int32_t)) + ", more than the limit of " +
                         formatBytes(memory_limit) + "; allowed: more tasks, larger chunks or a higher --memory-limit");
  for (std::size_t i = 1; i < out.start.size(); ++i) out.start[i] += out.start[i - 1];
  out.segments.resize(pairs);
  std::vector<std::int64_t> fill(out.start.begin(), out.start.end() - 1);
  for (std::int32_t s = 1; s < t.nodeCount(); ++s) {
    if (t.isRoot(s)) continue;
    forEachChunkReached(t, g, layout, s, [&](std::int64_t c) {
      if (c >= first && c < last) out.segments[std::size_t(fill[std::size_t(c - first)]++)] = s;
    });
  }
  return out;
}

// A window's voxels (x fastest, the window's size) copied into a whole chunk (z, y, x of
// `chunk` each), the rest set to `fill`.
std::vector<std::uint8_t> padToChunk(const void* data, std::size_t voxel_bytes, const VoxelWindow& w, std::int64_t chunk, const void* fill) {
  std::vector<std::uint8_t> out(std::size_t(chunk * chunk * chunk) * voxel_bytes);
  for (std::size_t v = 0; v < out.size(); v += voxel_bytes) std::memcpy(&out[v], fill, voxel_bytes);
  const auto* in = static_cast<const std::uint8_t*>(data);
  const std::int64_t nx = w.size(0), ny = w.size(1), nz = w.size(2);
  for (std::int64_t z = 0; z < nz; ++z)
    for (std::int64_t y = 0; y < ny; ++y)
      std::memcpy(&out[std::size_t((z * chunk + y) * chunk) * voxel_bytes], in + std::size_t((z * ny + y) * nx) * voxel_bytes,
                  std::size_t(nx) * voxel_bytes);
  return out;
}

Json axesJson() {
  Json axes = Json::array();
  for (const char* n : {"z", "y", "x"}) axes.push_back({{"name", n}, {"type", "space"}, {"unit", "millimeter"}});
  return axes;
}

Json multiscalesJson(const ChunkedVolumeOptions& opt, int channel, int levels) {
  const VolumeGrid& g = opt.grid;
  Json datasets = Json::array();
  for (int l = 0; l < levels; ++l) {
    // Voxel 0 of level l is the block of 2^l voxels of level 0 from voxel 0: its centre lies
    // (2^l − 1)/2 voxels past the centre of voxel 0.
    const double f = std::ldexp(1.0, l);
    Json scale = {g.spacing_mm.z * f, g.spacing_mm.y * f, g.spacing_mm.x * f};
    Json shift = {g.origin_mm.z + (f - 1) / 2 * g.spacing_mm.z, g.origin_mm.y + (f - 1) / 2 * g.spacing_mm.y,
                  g.origin_mm.x + (f - 1) / 2 * g.spacing_mm.x};
    datasets.push_back(
        {{"path", std::to_string(l)},
         {"coordinateTransformations", Json::array({{{"type", "scale"}, {"scale", scale}}, {{"type", "translation"}, {"translation", shift}}})}});
  }
  const Reduce r = kChannels[channel].reduce;
  const char* method = r == Reduce::Max    ? "maximum of the 2x2x2 voxels below (thin vessels stay visible)"
                       : r == Reduce::Mode ? "most frequent non-zero label of the 2x2x2 voxels below, the lower on a tie"
                       : r == Reduce::Mean ? "mean of the 2x2x2 voxels below (those inside the volume)"
                                           : "the image of the level's fraction (itself the mean of the voxels below)";
  Json ms = {{"version", "0.4"},
             {"name", kChannels[channel].name},
             {"axes", axesJson()},
             {"datasets", datasets},
             {"type", r == Reduce::Mode || r == Reduce::Max ? "max" : "mean"},
             {"metadata", {{"description", kChannels[channel].meaning}, {"method", method}}}};
  return Json::array({ms});
}

void writeJsonFile(const fs::path& file, const Json& j) {
  fs::create_directories(file.parent_path());
  writeFileAtomically(file, j.dump(2) + "\n");
}

Json sortedJson(const Json& j) { return nlohmann::json::parse(j.dump()); }

}  // namespace

ChunkedVolumeOptions chunkedVolumeOptions(const ImageParameters& ip, const VolumeGrid& grid, std::uint64_t memory_limit) {
  ChunkedVolumeOptions o;
  o.grid = grid;
  o.raster = RasterOptions{ip.supersampling, ip.centerline_connectivity};
  o.chunk = ip.zarr_chunk;
  o.levels = ip.zarr_levels;
  o.codec = *findZarrCodec(ip.zarr_compression);
  o.background = ip.background;
  o.vessel = ip.vessel;
  o.dtype = ip.dtype;
  o.memory_limit = memory_limit;
  return o;
}

Json ChunkedVolumeSummary::toJson() const {
  return {{"chunks", chunks},
          {"task_chunks", task_chunks},
          {"resumed_chunks", resumed_chunks},
          {"occupied_chunks", occupied_chunks},
          {"stored_chunk_files", stored_chunks},
          {"stored_bytes", stored_bytes},
          {"voxels_rasterised", voxels},
          {"mask_voxels", mask_voxels},
          {"memory_estimate_bytes", memory_estimate},
          {"seconds", seconds}};
}

Json PyramidSummary::toJson() const {
  return {{"levels", levels}, {"shapes_zyx", shapes}, {"stored_chunk_files", stored_chunks}, {"stored_bytes", stored_bytes}, {"seconds", seconds}};
}

Json chunkedJob(const ChunkedVolumeOptions& opt, const Json& input) {
  const VolumeGrid& g = opt.grid;
  return {{"input", input},
          {"grid",
           {{"size", g.dims},
            {"voxel_size_mm", {g.spacing_mm.x, g.spacing_mm.y, g.spacing_mm.z}},
            {"origin_mm", {g.origin_mm.x, g.origin_mm.y, g.origin_mm.z}}}},
          {"supersampling", opt.raster.supersampling},
          {"centerline_connectivity", opt.raster.centerline_connectivity},
          {"chunk", opt.chunk},
          {"levels", pyramidLevels(opt)},
          {"compression", {{"codec", zarrCodecName(opt.codec)}, {"level", opt.codec_level}}},
          {"image", {{"background", opt.background}, {"vessel", opt.vessel}, {"dtype", opt.dtype}}}};
}

std::int32_t pyramidLevels(const ChunkedVolumeOptions& opt) {
  if (opt.levels > 0) return opt.levels;
  std::int32_t levels = 1;
  auto s = levelShape(opt.grid, 0);
  while (std::max({s[0], s[1], s[2]}) > opt.chunk) {
    for (auto& n : s) n = (n + 1) / 2;
    ++levels;
  }
  return levels;
}

std::uint64_t chunkedVolumeBytes(const ChunkedVolumeOptions& opt) {
  const std::uint64_t c3 = std::uint64_t(opt.chunk) * opt.chunk * opt.chunk;
  // Level 0, per thread (a chunk each): every channel (19 bytes a voxel with a float image), the
  // image's conversion, a padded copy and a compressed copy of each channel.
  const std::uint64_t threads = std::max<std::uint64_t>(1, std::uint64_t(tbb::this_task_arena::max_concurrency()));
  const std::uint64_t level0 = threads * c3 * (19 + 4 + 19 + 19);
  // Pyramid: per thread, eight children and the reduced chunk of a float channel, twice (fraction
  // and image together).
  const std::uint64_t pyramid = threads * 2 * c3 * 4 * 10;
  return std::max(level0, pyramid) + (64u << 20);
}

void openChunkedVolume(const fs::path& store, const ChunkedVolumeOptions& opt, const Json& job) {
  if (opt.chunk <= 0 || opt.chunk % kBrick != 0 || opt.chunk > 1024)
    throw InputError(store.string(), 0, "chunk edge " + std::to_string(opt.chunk) + " voxels; allowed: a multiple of 8 from 8 to 1024");
  if (opt.codec_level < 0 || opt.codec_level > 9)
    throw InputError(store.string(), 0, "compression level " + std::to_string(opt.codec_level) + "; allowed: 0 to 9");
  if (opt.levels < 0 || opt.levels > 20)
    throw InputError(store.string(), 0, "pyramid levels " + std::to_string(opt.levels) + "; allowed: 0 (automatic) to 20");
  const fs::path record = recordDir(store) / "job.json";
  const Json wanted = sortedJson(job);
  std::error_code ec;
  if (fs::exists(store, ec)) {
    if (!fs::is_directory(store)) throw InputError(store.string(), 0, "is a file; allowed: a new directory, or a store of the same job to resume");
    if (fs::exists(record)) {
      std::ifstream in(record);
      Json held;
      try {
        held = sortedJson(Json::parse(in));
      } catch (const std::exception&) { throw InputError(record.string(), 0, "is not a job record; allowed: the record angiosynth wrote"); }
      if (held != wanted)
        throw InputError(store.string(), 0,
                         "holds another rasterisation (its .angiosynth/job.json differs: input, grid or settings); allowed: the same job, "
                         "to resume it, or a new --out");
    } else {
      // Another task of the job may have just made the directory: only its record folder is there.
      for (const auto& e : fs::directory_iterator(store))
        if (e.path().filename() != ".angiosynth")
          throw InputError(store.string(), 0,
                           "is not empty and holds no angiosynth store; allowed: a new or empty directory (nothing there is replaced)");
    }
  }
  fs::create_directories(recordDir(store));
  if (!fs::exists(record)) writeJsonFile(record, job);
  const int levels = pyramidLevels(opt);
  const double image_fill = typedBackground(opt);
  for (int c = 0; c < kChannelCount; ++c)
    for (int l = 0; l < levels; ++l) arrayOf(store, opt, c, l, image_fill).writeMetadata();
  const Json group = {{"zarr_format", 2}};
  for (const char* dir : {"", "fraction", "radius", "labels", "labels/mask", "labels/centerline", "labels/instances", "labels/classes"})
    writeJsonFile(store / dir / ".zgroup", group);
  for (int c = 0; c < kChannelCount; ++c) {
    Json attrs = {{"multiscales", multiscalesJson(opt, c, levels)}};
    if (kChannels[c].label) {
      Json colours = Json::array();
      if (std::string(kChannels[c].name) == "classes")
        colours = Json::array({{{"label-value", 1}, {"rgba", {220, 40, 40, 255}}}, {{"label-value", 2}, {"rgba", {40, 80, 220, 255}}}});
      else if (std::string(kChannels[c].name) != "instances")
        colours = Json::array({{{"label-value", 1}, {"rgba", {255, 255, 255, 255}}}});
      attrs["image-label"] = {{"version", "0.4"}, {"source", {{"image", "../../"}}}};
      if (!colours.empty()) attrs["image-label"]["colors"] = colours;
    }
    if (c == 0) {
      attrs["angiosynth"] = {{"job", ".angiosynth/job.json"},
                             {"channels", "image here; fraction/ and radius/ (floats); labels/ mask, centerline, instances, classes"},
                             {"voxel_centres", "translation = centre of voxel 0 of each level, in mm (world frame RAS+)"}};
    }
    writeJsonFile(store / kChannels[c].group / ".zattrs", attrs);
  }
  writeJsonFile(store / "labels" / ".zattrs", Json{{"labels", {"mask", "centerline", "instances", "classes"}}});
}

std::vector<int> unfinishedTasks(const fs::path& store, const ChunkedVolumeOptions& opt, int tasks) {
  const ChunkLayout layout(opt);
  std::vector<int> open;
  for (int i = 0; i < tasks; ++i) {
    const ChunkTask t{i, tasks};
    if (readCount(progressFile(store, t)) < layout.end(t) - layout.begin(t)) open.push_back(i);
  }
  return open;
}

ChunkedVolumeSummary rasterizeChunks(const Forest& forest, const fs::path& store, const ChunkedVolumeOptions& opt, ChunkTask task) {
  const auto t0 = std::chrono::steady_clock::now();
  if (task.count < 1 || task.index < 0 || task.index >= task.count)
    throw InputError(store.string(), 0, "task " + std::to_string(task.index) + " of " + std::to_string(task.count) + "; allowed: 0 <= task < tasks");
  const VascularTree& tree = forest.vessels;
  const VolumeGrid& g = opt.grid;
  const ChunkLayout layout(opt);
  ChunkedVolumeSummary sum;
  sum.chunks = layout.total;
  const std::int64_t first = layout.begin(task), last = layout.end(task);
  sum.task_chunks = last - first;
  const fs::path progress = progressFile(store, task);
  const std::int64_t done = std::min(readCount(progress), sum.task_chunks);
  sum.resumed_chunks = done;
  const std::uint64_t limit = opt.memory_limit ? opt.memory_limit : defaultMemoryLimitBytes();
  sum.memory_estimate = chunkedVolumeBytes(opt);
  if (sum.memory_estimate > limit)
    throw InputError(store.string(), 0,
                     "a chunk of " + std::to_string(opt.chunk) + "^3 voxels needs about " + formatBytes(sum.memory_estimate) +
                         " of memory, more than the limit of " + formatBytes(limit) + "; allowed: smaller chunks or a higher --memory-limit");
  const ChunkSegments near = segmentsOfChunks(tree, g, layout, first + done, last, limit, store);
  const std::vector<std::uint8_t> classes = segmentClasses(tree, forest.trees);
  const double image_fill = typedBackground(opt);
  std::array<ZarrArray, kChannelCount> arrays;
  for (int c = 0; c < kChannelCount; ++c) arrays[std::size_t(c)] = arrayOf(store, opt, c, 0, image_fill);
  if (opt.progress) opt.progress(done, sum.task_chunks);
  // The fill of the image's padding, as its voxel type stores it.
  std::uint8_t image_pad[4] = {0, 0, 0, 0};
  {
    const ZarrArray& a = arrays[0];
    const float f = float(a.fill);
    const auto s16 = std::int16_t(a.fill);
    const auto u16 = std::uint16_t(std::max(0.0, a.fill));
    if (a.type == VoxelType::Float32) std::memcpy(image_pad, &f, 4);
    if (a.type == VoxelType::Int16) std::memcpy(image_pad, &s16, 2);
    if (a.type == VoxelType::UInt16) std::memcpy(image_pad, &u16, 2);
    if (a.type == VoxelType::UInt8) image_pad[0] = std::uint8_t(u16);
  }
  struct ChunkResult {
    std::int64_t mask_voxels = 0, voxels = 0, stored_chunks = 0;
    std::uint64_t stored_bytes = 0;
    bool occupied = false;
  };
  // The volumes of a chunk, reused by the next chunk: made afresh, each of their pages would take a
  // page fault per chunk. A pool, not one per thread: a thread waiting in a chunk's inner
  // parallel loop may start another chunk.
  struct ChunkBuffers {
    GroundTruthVolumes gt;
    TypedImage image;
  };
  std::mutex pool_mutex;
  std::vector<std::unique_ptr<ChunkBuffers>> pool;
  const auto rasterizeOne = [&](std::int64_t id) {
    ChunkResult r;
    const auto segments = near.of(id - first - done);
    if (segments.empty()) return r;
    std::unique_ptr<ChunkBuffers> buffers;
    {
      const std::lock_guard lock(pool_mutex);
      if (pool.empty()) {
        buffers = std::make_unique<ChunkBuffers>();
      } else {
        buffers = std::move(pool.back());
        pool.pop_back();
      }
    }
    const VoxelWindow w = layout.window(id, g);
    GroundTruthVolumes& gt = buffers->gt;
    rasterizeGroundTruth(tree, g, w, segments, opt.raster, gt);
    fillClasses(gt, tree, classes, g, w, segments);
    TypedImage& image = buffers->image;
    makeTypedImage(image, gt.fraction, opt.background, opt.vessel - opt.background, opt.dtype, "");
    const std::array<const void*, kChannelCount> data{image.view.data,           gt.fraction.data.data(),  gt.radius.data.data(), gt.mask.data.data(),
                                                      gt.centerline.data.data(), gt.instances.data.data(), gt.classes.data.data()};
    for (auto m : gt.mask.data) r.mask_voxels += m;
    r.voxels = w.voxelCount();
    r.occupied = true;
    const auto c = layout.coords(id);
    std::array<std::uint64_t, kChannelCount> stored{};
    tbb::parallel_for(0, kChannelCount, [&](int ch) {
      const ZarrArray& a = arrays[std::size_t(ch)];
      const std::array<std::int64_t, 3> key{c[2], c[1], c[0]};
      if (w.voxelCount() == std::int64_t(opt.chunk) * opt.chunk * opt.chunk) {
        stored[std::size_t(ch)] = a.writeChunk(key, data[std::size_t(ch)]);
      } else {
        const std::uint8_t zero[4] = {0, 0, 0, 0};
        const auto padded = padToChunk(data[std::size_t(ch)], voxelBytes(a.type), w, opt.chunk, ch == 0 ? image_pad : zero);
        stored[std::size_t(ch)] = a.writeChunk(key, padded.data());
      }
    });
    for (auto b : stored) {
      r.stored_bytes += b;
      r.stored_chunks += b > 0;
    }
    const std::lock_guard lock(pool_mutex);
    pool.push_back(std::move(buffers));
    return r;
  };
  // Chunks in batches, one per thread at a time (memory: a batch of chunks); progress is recorded
  // after each batch, so a rerun redoes at most one batch.
  const std::int64_t batch = std::max<std::int64_t>(1, tbb::this_task_arena::max_concurrency());
  std::vector<ChunkResult> results;
  for (std::int64_t id = first + done; id < last; id += batch) {
    const std::int64_t end = std::min(last, id + batch);
    results.assign(std::size_t(end - id), ChunkResult{});
    tbb::parallel_for(id, end, [&](std::int64_t c) { results[std::size_t(c - id)] = rasterizeOne(c); });
    for (const auto& r : results) {
      sum.mask_voxels += r.mask_voxels;
      sum.voxels += r.voxels;
      sum.stored_bytes += r.stored_bytes;
      sum.stored_chunks += r.stored_chunks;
      sum.occupied_chunks += r.occupied;
    }
    writeFileAtomically(progress, std::to_string(end - first) + "\n");
    if (opt.progress) opt.progress(end - first, sum.task_chunks);
  }
  if (sum.task_chunks == 0) writeFileAtomically(progress, "0\n");
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return sum;
}

namespace {

template <class T>
T modeOf(const T* v, int n) {
  T best = 0;
  int best_count = 0;
  for (int i = 0; i < n; ++i) {
    if (v[i] == 0) continue;
    int count = 0;
    for (int j = 0; j < n; ++j) count += v[j] == v[i];
    if (count > best_count || (count == best_count && v[i] < best)) best = v[i], best_count = count;
  }
  return best;
}

// One reduced chunk of a channel at `level` from the eight chunks below it (level − 1). Each
// child chunk makes one octant of the result (chunks have an even edge), so only the stored
// children cost anything.
template <class T>
std::vector<T> reduceChunk(const ZarrArray& below, const std::array<std::int64_t, 3>& key, Reduce how, std::int64_t C, bool& any) {
  std::vector<T> out, child(std::size_t(C * C * C));
  any = false;
  const auto grid = below.chunkGrid();
  const std::int64_t H = C / 2;
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const std::array<std::int64_t, 3> k{2 * key[0] + dz, 2 * key[1] + dy, 2 * key[2] + dx};
        if (k[0] >= grid[0] || k[1] >= grid[1] || k[2] >= grid[2]) continue;
        if (!below.readChunk(k, child.data())) continue;
        if (!any) out.assign(std::size_t(C * C * C), T(0));
        any = true;
        // The child's voxels inside the array below (the rest of a chunk at its edge is padding).
        std::array<std::int64_t, 3> valid{};
        for (int a = 0; a < 3; ++a) valid[a] = std::clamp<std::int64_t>(below.shape[a] - k[a] * C, 0, C);
        tbb::parallel_for(std::int64_t(0), std::min(H, (valid[0] + 1) / 2), [&](std::int64_t z) {
          for (std::int64_t y = 0; y < std::min(H, (valid[1] + 1) / 2); ++y)
            for (std::int64_t x = 0; x < std::min(H, (valid[2] + 1) / 2); ++x) {
              T v[8];
              int n = 0;
              for (int ez = 0; ez < 2; ++ez)
                for (int ey = 0; ey < 2; ++ey)
                  for (int ex = 0; ex < 2; ++ex) {
                    const std::int64_t sz = 2 * z + ez, sy = 2 * y + ey, sx = 2 * x + ex;
                    if (sz < valid[0] && sy < valid[1] && sx < valid[2]) v[n++] = child[std::size_t((sz * C + sy) * C + sx)];
                  }
              T r = 0;
              if (how == Reduce::Mean) {
                double sum = 0;
                for (int i = 0; i < n; ++i) sum += double(v[i]);
                r = T(sum / n);
              } else if (how == Reduce::Max) {
                r = *std::max_element(v, v + n);
              } else {
                r = modeOf(v, n);
              }
              out[std::size_t(((dz * H + z) * C + dy * H + y) * C + dx * H + x)] = r;
            }
        });
      }
  return out;
}

}  // namespace

PyramidSummary buildPyramid(const fs::path& store, const ChunkedVolumeOptions& opt, int tasks) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto open = unfinishedTasks(store, opt, tasks);
  if (!open.empty()) {
    std::string list;
    for (int i : open) list += (list.empty() ? "" : ", ") + std::to_string(i);
    throw InputError(store.string(), 0,
                     "level 0 is not finished: task(s) " + list + " of " + std::to_string(tasks) +
                         " have not run to the end; allowed: the pyramid once every task has finished (rerun those tasks; they resume)");
  }
  PyramidSummary sum;
  sum.levels = pyramidLevels(opt);
  for (int l = 0; l < sum.levels; ++l) sum.shapes.push_back(levelShape(opt.grid, l));
  const double image_fill = typedBackground(opt);
  const std::int64_t C = opt.chunk;
  for (int l = 1; l < sum.levels; ++l) {
    if (fs::exists(levelDoneFile(store, l))) continue;
    std::array<ZarrArray, kChannelCount> below, here;
    for (int c = 0; c < kChannelCount; ++c) {
      below[std::size_t(c)] = arrayOf(store, opt, c, l - 1, image_fill);
      here[std::size_t(c)] = arrayOf(store, opt, c, l, image_fill);
    }
    const auto grid = here[0].chunkGrid();
    const std::int64_t total = grid[0] * grid[1] * grid[2];
    for (std::int64_t id = 0; id < total; ++id) {
      const std::array<std::int64_t, 3> key{id / (grid[1] * grid[2]), (id / grid[2]) % grid[1], id % grid[2]};
      std::array<std::uint64_t, kChannelCount> stored{};
      // Channel 0 (the image) is made with the fraction (channel 1).
      tbb::parallel_for(1, kChannelCount, [&](int c) {
        bool any = false;
        const std::size_t ci = std::size_t(c);
        const ZarrArray& a = here[ci];
        switch (a.type) {
          case VoxelType::Float32: {
            const auto out = reduceChunk<float>(below[ci], key, kChannels[ci].reduce, C, any);
            if (!any) break;
            stored[ci] = a.writeChunk(key, out.data());
            if (c == 1) {
              Volume<float> f(VolumeGrid{{int(C), int(C), int(C)}, {}, {1, 1, 1}});
              std::copy(out.begin(), out.end(), f.data.begin());
              TypedImage image;
              makeTypedImage(image, f, opt.background, opt.vessel - opt.background, opt.dtype, "");
              stored[0] = here[0].writeChunk(key, image.view.data);
            }
            break;
          }
          case VoxelType::UInt32: {
            const auto out = reduceChunk<std::uint32_t>(below[ci], key, kChannels[ci].reduce, C, any);
            if (any) stored[ci] = a.writeChunk(key, out.data());
            break;
          }
          default: {
            const auto out = reduceChunk<std::uint8_t>(below[ci], key, kChannels[ci].reduce, C, any);
            if (any) stored[ci] = a.writeChunk(key, out.data());
            break;
          }
        }
      });
      for (auto b : stored) {
        sum.stored_bytes += b;
        sum.stored_chunks += b > 0;
      }
      if (opt.progress) opt.progress(id + 1, total);
    }
    writeFileAtomically(levelDoneFile(store, l), "done\n");
  }
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return sum;
}

}  // namespace angiosynth
