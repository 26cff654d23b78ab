#pragma once
// The degraded images of a sample, one per profile, with the warped labels and graph when a
// profile warps.
#include <filesystem>

#include <nlohmann/json.hpp>

#include "pipeline/volume_outputs.hpp"
#include "raster/ground_truth.hpp"

namespace angiosynth {

// Peak extra memory while one profile runs on grid g.
std::uint64_t degradedImageBytes(const Profile& p, const VolumeGrid& g);

void writeDegradedImages(const Forest& forest, const std::vector<std::uint8_t>& segment_classes, const GroundTruthVolumes& gt,
                         const VolumeRequest& req, const std::filesystem::path& dir, nlohmann::ordered_json& files,
                         nlohmann::ordered_json& degradation, nlohmann::ordered_json* seconds = nullptr);

}  // namespace angiosynth
