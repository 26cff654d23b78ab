#pragma once
// The measures the score metrics are made of: overlap counts, border voxels and their distances,
// clDice from skeletons, recall by calibre, and the grid check every truth volume passes.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/nifti_reader.hpp"
#include "raster/volume.hpp"

namespace angiosynth {

// A ratio, or null when its denominator is 0 (undefined): how every score states an empty case.
nlohmann::ordered_json ratio(double num, double den);

// n, mean, median, standard deviation (n − 1), min and max of the values (the cases' numbers).
nlohmann::ordered_json summaryOf(std::vector<double> values);

// Voxels > 0 of a volume as a binary mask.
Volume<std::uint8_t> binaryMask(const Volume<float>& v);

// The smallest voxel edge (mm).
double smallestEdge(const VolumeGrid& g);

// Overlap of two binary volumes on one grid: tp, fp, fn, Dice, Jaccard, precision, recall.
nlohmann::ordered_json overlapScores(const Volume<std::uint8_t>& pred, const Volume<std::uint8_t>& truth, bool topcow);

// Border voxels: foreground voxels with a background neighbour (6 face neighbours; 26 with
// `all_neighbours`), voxels beyond the grid counting as background.
Volume<std::uint8_t> borderVoxels(const Volume<std::uint8_t>& v, bool all_neighbours);

// The distance (mm, between voxel centres, the grid's spacing per axis) from each border voxel
// of `from` to the nearest border voxel of `to`, in voxel order.
std::vector<double> directedBorderDistances(const Volume<std::uint8_t>& from_border, const Volume<std::uint8_t>& to_border);

// HD, HD95 (the larger of the two directed 95th percentiles, linear interpolation between order
// statistics as NumPy's default), ASSD, MASD and NSD at tolerance τ between the borders of two
// volumes. Empty masks: both empty give 0 mm and NSD 1; one empty gives null (TopCoW:
// `missing_mm`, 90 mm in TopCoW and 290 mm in TopBrain).
nlohmann::ordered_json surfaceScores(const Volume<std::uint8_t>& pred, const Volume<std::uint8_t>& truth, double tolerance_mm, bool topcow,
                                     double missing_mm = 90);

// clDice (Shit et al. 2021) from the two skeletons and masks: topology precision, sensitivity,
// their harmonic mean (null when a skeleton is empty; TopCoW: that share 0).
nlohmann::ordered_json clDice(const Volume<std::uint8_t>& pred_skeleton, const Volume<std::uint8_t>& truth,
                              const Volume<std::uint8_t>& truth_skeleton, const Volume<std::uint8_t>& pred, bool topcow);

// 95th percentile, linear interpolation between order statistics (NumPy's default).
double percentile95(std::vector<double> values);

// Recall of the truth's exact centreline voxels by calibre: bins by the radius there in units of
// `scale` mm (`lower`: increasing lower edges; the last bin is open), each with its centreline
// voxels, the share in the prediction (recall) and in the truth mask (truth_coverage).
nlohmann::ordered_json calibreRecall(const Volume<std::uint8_t>& pred, const Volume<std::uint8_t>& truth, const Volume<float>& centre,
                                     const Volume<float>& radius, const std::vector<double>& lower, double scale, const char* unit);

// Boundary IoU's inner band (Cheng et al. 2021): the voxels of v within d mm (Euclidean, between
// voxel centres) of a background voxel, the space beyond the grid counting as background. A
// one-slice grid is measured in its plane.
Volume<std::uint8_t> innerBoundaryBand(const Volume<std::uint8_t>& v, double d_mm);

// The IoU of the shells of the bounding boxes of a and b as the TopCoW 2024 evaluation computes it:
// each shell the voxels of its box within ceil(ratio × size) voxels of a face along that face's
// axis (ratio 0.5: the whole box, the boxes' IoU). Unset when a mask is empty.
std::optional<double> boxBoundaryIoU(const Volume<std::uint8_t>& a, const Volume<std::uint8_t>& b, double ratio);

// Refuses `volume` (read from volume_file) unless it lies on the truth's grid: the same voxels,
// and the centres of the grid's corner voxels within `tolerance_voxels` (of the smallest edge)
// under the two voxel-to-world affines, either file's sform or qform.
void checkSameGrid(const NiftiVolume& volume, const NiftiVolume& truth, const std::string& volume_file, const std::string& truth_file,
                   double tolerance_voxels);

}  // namespace angiosynth
