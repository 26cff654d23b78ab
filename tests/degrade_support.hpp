#pragma once
// What the degradation tests share: profiles written from text, empty ground truth on a grid,
// and one profile run on it.
#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>

#include "degrade/degrade.hpp"
#include "pipeline/volume_outputs.hpp"

namespace angiosynth::test {

inline std::filesystem::path writeTemp(const std::string& name, const std::string& text) {
  // A directory per process keeps tests that ctest runs in parallel off each other's files; the
  // file keeps its name, which names the profile and so keys its random draws (a pid in the name
  // made every process draw another warp).
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("angiosynth_degrade_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path p = dir / name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

inline Profile profileFrom(const std::string& name, const std::string& text) { return readProfileToml(writeTemp(name + ".toml", text)); }

// Every ground-truth volume on the grid, empty.
inline GroundTruthVolumes flatTruth(const std::array<std::int32_t, 3>& dims, const Vec3& spacing = Vec3(1, 1, 1)) {
  VolumeGrid g;
  g.dims = dims;
  g.spacing_mm = spacing;
  GroundTruthVolumes gt;
  gt.fraction = Volume<float>(g);
  gt.mask = Volume<std::uint8_t>(g);
  gt.centerline = Volume<std::uint8_t>(g);
  gt.radius = Volume<float>(g);
  gt.instances = Volume<std::uint32_t>(g);
  return gt;
}
inline GroundTruthVolumes flatTruth(int n, const Vec3& spacing = Vec3(1, 1, 1)) { return flatTruth({n, n, n}, spacing); }

// n³ voxels of h mm from the origin: voxel centres at (i + ½)·h.
inline VolumeGrid cubeGrid(int n, double h) {
  VolumeGrid g;
  g.dims = {n, n, n};
  g.spacing_mm = Vec3(h, h, h);
  g.origin_mm = g.spacing_mm * 0.5;
  return g;
}

// A parameter file for `generate`: a 40-terminal CCO sphere imaged at 0.3 mm, NIfTI only, for
// runs of profiles through the command line.
inline const char* const kSmallCcoSample =
    "seed = 4\n[domain]\nshape = \"sphere\"\nradius = \"6 mm\"\nvoxel_size = \"0.25 mm\"\n"
    "[tree]\nmethod = \"cco\"\nterminals = 40\n"
    "[physics]\nperfusion_pressure = \"100 mmHg\"\nterminal_pressure = \"60 mmHg\"\nperfusion_flow = \"20 mL/min\"\n"
    "[image]\nformats = [\"nifti\"]\nvoxel_size = \"0.3 mm\"\n";

inline const VascularTree kNoTree = [] {
  VascularTree t;
  t.addNode(Vec3(0, 0, 0), -1);
  return t;
}();

// The profile run on the ground truth (float32 image).
inline DegradedImage degradeWith(const Profile& p, const GroundTruthVolumes& gt, const VascularTree& tree = kNoTree, std::uint64_t seed = 7) {
  DegradeInput in;
  in.tree = &tree;
  in.truth = &gt;
  in.seed = seed;
  in.dtype = "float32";
  return degradeImage(p, in);
}

}  // namespace angiosynth::test
