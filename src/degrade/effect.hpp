#pragma once
// A degradation effect: a named operation on the image (and, for warps, on everything aligned
// with it), with declared parameters. Each effect lives in its own file and registers here.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/distractor_kind.hpp"
#include "core/rng.hpp"
#include "core/vascular_tree.hpp"
#include "degrade/effect_params.hpp"
#include "raster/volume.hpp"

namespace angiosynth {

class BSplineWarp;

// The image being degraded and the ground truth aligned with it. Until a warp, `fraction`
// and `tree` point at the clean raster and tree; a warp replaces them with warped copies.
struct DegradeState {
  VolumeGrid grid;
  Volume<float> image;                      // intensities in the profile's scale
  double background = 0, vessel = 255;      // the profile's tissue and full-vessel intensities
  const Volume<float>* fraction = nullptr;  // vessel partial volume, aligned with `image`
  const VascularTree* tree = nullptr;       // vessels, aligned with `image`
  // Segment id of the clean tree for each segment of `tree` (empty: the same ids).
  std::vector<std::int32_t> segment_origin;
  // Set by a warp: the pull-back map (clean position of each warped voxel) and owned copies.
  std::shared_ptr<const BSplineWarp> warp;
  std::shared_ptr<Volume<float>> warped_fraction;
  std::shared_ptr<VascularTree> warped_tree;
  std::int32_t originalSegment(std::int32_t s) const { return segment_origin.empty() ? s : segment_origin[s]; }
  // What the distractor effects placed (DistractorKind per voxel), allocated by the first of them;
  // aligned with `image` (a warp moves it too). Background in every vessel label.
  Volume<std::uint8_t> distractors;
  void markDistractor(std::int64_t v, std::uint8_t kind) {
    if (distractors.data.empty()) distractors = Volume<std::uint8_t>(grid);
    distractors.data[v] = kind;
  }
};

struct EffectContext {
  DegradeState& state;
  Rng& rng;                        // the effect's own stream, after its parameters were drawn
  nlohmann::ordered_json& record;  // drawn values go here (sample.json)
  std::string file;                // the profile, for errors
  int line = 0;
};

struct EffectType {
  const char* name;
  const char* summary;  // one line for the docs and `--help`
  std::vector<ParamDecl> params;
  void (*apply)(const Drawn& p, EffectContext& ctx);
  bool moves_geometry = false;                // a warp: at most one per profile
  bool noise = false;                         // random noise (left out of the visible label's noise-free runs)
  std::uint64_t working_bytes_per_voxel = 0;  // what it holds beside the image while it runs (a k-space)
  bool places_distractors = false;            // writes the distractor label (one byte per voxel, kept)
};

// Every effect, in the order the docs list them.
const std::vector<const EffectType*>& effectTypes();
const EffectType* findEffectType(const std::string& name);
// Markdown list of every effect with its parameters (`angiosynth effects`, docs/degradation.md).
std::string effectReference();
// A profile's [[effect]] block that applies `t` with its defaults and a value of the right kind
// for each parameter it requires (tests and benchmarks run every effect through it).
std::string exampleEffectToml(const EffectType& t);

// Applies f(v) to every voxel index in parallel; f must depend on v only (not on scheduling).
template <class F>
void forEachVoxel(std::int64_t count, F&& f);
// The same with the voxel's (i, j, k): rows in parallel, i contiguous within a row.
template <class F>
void forEachVoxelIjk(const VolumeGrid& g, F&& f);

}  // namespace angiosynth

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace angiosynth {

template <class F>
void forEachVoxel(std::int64_t count, F&& f) {
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, count, 1 << 14), [&](const tbb::blocked_range<std::int64_t>& r) {
    for (std::int64_t v = r.begin(); v < r.end(); ++v) f(v);
  });
}

template <class F>
void forEachVoxelIjk(const VolumeGrid& g, F&& f) {
  const std::int64_t nx = g.dims[0], ny = g.dims[1];
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, ny * g.dims[2]), [&](const tbb::blocked_range<std::int64_t>& r) {
    for (std::int64_t row = r.begin(); row < r.end(); ++row) {
      const std::int64_t j = row % ny, k = row / ny;
      for (std::int64_t i = 0; i < nx; ++i) f(row * nx + i, i, j, k);
    }
  });
}

}  // namespace angiosynth
