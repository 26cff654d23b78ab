#pragma once
// Volumes larger than memory: the ground truth rasterised chunk by chunk into an OME-Zarr store
// (OME-NGFF 0.4 on Zarr format 2), in memory bounded by the chunk, not the volume. Every chunk's
// voxels equal the whole grid's (raster/ground_truth.hpp), so the store holds the same values the
// in-memory rasterisation would. Chunks are split into contiguous ranges, one per task, so a
// cluster array (Slurm, Kubernetes, GNU parallel) rasterises one volume in parallel; a task
// records its progress after every chunk and a rerun of a killed task resumes there. A last step
// builds the multiscale pyramid once every task is done.
//
// The store:  image (the typed image, levels 0, 1, …), fraction/ and radius/ (floats), and
// labels/{mask, centerline, instances, classes} (OME-NGFF image-labels), each a multiscale of
// arrays "0", "1", … with chunks keyed "z/y/x"; .angiosynth/ holds the job record and progress.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/image_settings.hpp"
#include "core/forest.hpp"
#include "grow/common/growth_report.hpp"
#include "io/zarr_array.hpp"
#include "raster/capsule_rasterizer.hpp"
#include "raster/volume.hpp"

namespace angiosynth {

struct ChunkedVolumeOptions {
  VolumeGrid grid;
  RasterOptions raster;
  std::int32_t chunk = 128;  // voxels along each edge of a chunk, a multiple of 8
  std::int32_t levels = 0;   // pyramid levels with the full resolution; 0: halve until one chunk holds the volume
  ZarrCodec codec = ZarrCodec::Blosc;
  int codec_level = 5;
  double background = 0, vessel = 1;  // image = background + fraction × (vessel − background)
  std::string dtype = "float32";      // of the image: uint8, uint16, int16, float32
  std::uint64_t memory_limit = 0;     // bytes; 0: 75 % of physical memory
  ProgressFn progress;                // chunks done, chunks of the task (or of the level)
};

// The options [image] gives (chunk, levels, compression, intensities, supersampling) on `grid`.
ChunkedVolumeOptions chunkedVolumeOptions(const ImageParameters& image, const VolumeGrid& grid, std::uint64_t memory_limit);

// Task `index` of `count` takes the `index`-th of `count` contiguous ranges of level-0 chunks.
struct ChunkTask {
  int index = 0, count = 1;
};

struct ChunkedVolumeSummary {
  std::int64_t chunks = 0;           // level-0 chunks of the whole volume
  std::int64_t task_chunks = 0;      // of this task
  std::int64_t resumed_chunks = 0;   // finished by an earlier run of this task, not redone
  std::int64_t occupied_chunks = 0;  // rasterised here: some vessel reaches them
  std::int64_t stored_chunks = 0;    // chunk files written, all channels
  std::uint64_t stored_bytes = 0;
  std::int64_t voxels = 0;  // in the chunks rasterised here
  std::int64_t mask_voxels = 0;
  std::uint64_t memory_estimate = 0;  // bytes, checked before allocating
  double seconds = 0;
  nlohmann::ordered_json toJson() const;
};

struct PyramidSummary {
  std::int32_t levels = 1;
  std::vector<std::array<std::int64_t, 3>> shapes;  // per level, z, y, x
  std::int64_t stored_chunks = 0;
  std::uint64_t stored_bytes = 0;
  double seconds = 0;
  nlohmann::ordered_json toJson() const;
};

// Pyramid levels the options give for their grid (levels = 0 resolved).
std::int32_t pyramidLevels(const ChunkedVolumeOptions& opt);
// Bytes one task holds at a time (a chunk of every channel and its compressed copies; the pyramid's
// eight children per channel), for the memory check.
std::uint64_t chunkedVolumeBytes(const ChunkedVolumeOptions& opt);

// The job a store records: `input` (which tree) and every option that changes the store's bytes.
nlohmann::ordered_json chunkedJob(const ChunkedVolumeOptions& opt, const nlohmann::ordered_json& input);

// Creates the store with every array's and group's metadata, or opens the one an earlier task of
// the same job created: `job` (what is rasterised: input, grid, settings) is recorded in the store
// and must match. Throws InputError for a directory that is not such a store (nothing is written
// there) and for options the store cannot take.
void openChunkedVolume(const std::filesystem::path& store, const ChunkedVolumeOptions& opt, const nlohmann::ordered_json& job);

// Rasterises the level-0 chunks of `task` into the store, after those an earlier run of the same
// task finished. Throws InputError before allocating when the chunk would exceed the memory limit.
ChunkedVolumeSummary rasterizeChunks(const Forest& forest, const std::filesystem::path& store, const ChunkedVolumeOptions& opt, ChunkTask task);

// Builds levels 1, 2, … from level 0 (fraction and image: the mean of the voxels below; mask,
// centreline and radius: the maximum, so thin vessels stay visible; instances and classes: the
// most frequent non-zero label, the lower on a tie). Throws InputError naming the tasks of
// `tasks` that have not finished.
PyramidSummary buildPyramid(const std::filesystem::path& store, const ChunkedVolumeOptions& opt, int tasks);

// Whether every level-0 task of `tasks` has finished.
std::vector<int> unfinishedTasks(const std::filesystem::path& store, const ChunkedVolumeOptions& opt, int tasks);

}  // namespace angiosynth
