#include "pipeline/degraded_outputs.hpp"

#include <algorithm>
#include <optional>

#include "degrade/degrade.hpp"
#include "io/graph_writers.hpp"
#include "files/text_file.hpp"
#include "pipeline/label_outputs.hpp"
#include "pipeline/volume_files.hpp"

namespace angiosynth {

using Json = nlohmann::ordered_json;

std::uint64_t degradedImageBytes(const Profile& p, const VolumeGrid& g) {
  bool warps = false, fields = false, distractors = false;
  std::uint64_t working = 0;  // effects run one after another: the largest working set counts
  for (const auto& e : p.effects) {
    warps |= e.type->moves_geometry;
    working = std::max(working, e.type->working_bytes_per_voxel);
    distractors |= e.type->places_distractors;
    fields |= std::string(e.type->name) == "bias" || std::string(e.type->name) == "texture";
  }
  // Float image + a working copy (blur, warp) + the typed image; a warp adds its fraction and
  // labels. B-spline lattices are at least a voxel apart, so a field holds at most about one
  // coefficient per voxel plus its plane buffer (8 bytes); a warp keeps three. The distractor
  // label is a byte per voxel (two while a warp resamples it).
  const std::uint64_t per_voxel = 4 + 4 + 4 + (warps ? 4 + 1 + 1 + 4 + 4 + 24 : 0) + (fields ? 16 : 0) + working + (distractors ? 2 : 0);
  return per_voxel * static_cast<std::uint64_t>(g.voxelCount());
}

namespace {

// The files of one degraded image: its volumes (or VascuSynth's slices), previews, and for a warp
// the warped tree's graphs and the warp itself.
void writeDegradedFiles(const DegradedImage& d, const TypedImage& image, const std::vector<Channel>& channels, const Forest& forest,
                        const GroundTruthVolumes& gt, const std::string& profile, const VolumeRequest& req, const std::filesystem::path& dir,
                        nlohmann::ordered_json& files) {
  const ImageParameters& ip = req.image;
  const std::string suffix = "_" + profile;
  // Previews span the profile's background to vessel intensities.
  const double lo = std::min(d.background, d.vessel), hi = std::max(d.background, d.vessel);
  if (req.vascusynth) {
    writeVascuSynthSlices(image.view, d.image, lo, hi, profile, *req.vascusynth, dir, files);
  } else {
    writeChannels(channels, ip.formats, dir, files);
    if (std::find(ip.formats.begin(), ip.formats.end(), "png") != ip.formats.end())
      writeMips(d.image, previewClasses(forest.trees, d.labels ? *d.labels : gt), lo, hi, suffix, dir, files);
  }
  if (d.tree) {
    const std::string gxl = "tree" + suffix + ".gxl";
    writeTextFile(dir / gxl, [&](std::ostream& o) { writeGxl(o, *d.tree, forest.trees, req.frame, "tree" + suffix); });
    files["gxl" + suffix] = gxl;
    const std::string warp = "warp" + suffix + ".json";
    writeTextFile(dir / warp, [&](std::ostream& o) { o << d.warp->describe().dump(1) << "\n"; });
    files["warp" + suffix] = warp;
    writeGraphFiles(*d.tree, forest.trees, gt.fraction.grid, ip.graph_formats, suffix, dir, files);
  }
}

}  // namespace

void writeDegradedImages(const Forest& forest, const std::vector<std::uint8_t>& segment_classes, const GroundTruthVolumes& gt,
                         const VolumeRequest& req, const std::filesystem::path& dir, nlohmann::ordered_json& files,
                         nlohmann::ordered_json& degradation, nlohmann::ordered_json* seconds) {
  const ImageParameters& ip = req.image;
  for (const Profile& profile : req.profiles) {
    DegradeInput in;
    in.tree = &forest.vessels;
    in.truth = &gt;
    in.seed = req.seed;
    in.sample = req.sample;
    in.background = ip.background;
    in.vessel = ip.vessel;
    in.dtype = ip.dtype;
    DegradedImage d = degradeImage(profile, in);
    const std::string suffix = "_" + profile.name;
    TypedImage image;
    makeTypedImage(image, d.image, 0, 1, d.dtype, "angiosynth image, profile " + profile.name);
    std::vector<Channel> channels{{"image" + suffix, image.view}};
    if (d.labels && !req.vascusynth) {
      fillClasses(*d.labels, *d.tree, segment_classes, &d.segment_origin);  // labels: clean segment ids
      for (auto& c : labelChannels(*d.labels, suffix)) channels.push_back(c);
    }
    // Structures that are not vessels, so that false positives on them can be counted.
    if (d.distractors && !req.vascusynth)
      channels.push_back(
          {"distractors" + suffix, viewOf(*d.distractors, true, "angiosynth distractors: 1 blob, 2 tube, 3 plate, 4 bone, 5 calcification")});
    // The policy's label of this image, where it is not the clean one.
    Label label;
    if (!req.vascusynth && (ip.labels.perProfile() || (ip.labels.writesLabel() && d.labels))) {
      const GroundTruthVolumes& truth = d.labels ? *d.labels : gt;
      std::optional<ProfileVisibility> vis;  // visible: this image's contrast and noise
      VisibilityEvidence evidence;
      if (ip.labels.perProfile()) {
        vis = profileVisibility(profile, in, d.image, truth.fraction);
        evidence = {&vis->contrast, vis->noise_sigma};
      }
      label = makeLabel(ip.labels, truth, req.label_numbering, vis ? &evidence : nullptr);
      Json& rec = d.record["label"];
      rec = labelLengthKept(label, ip.labels, req.label_numbering, d.tree ? *d.tree : forest.vessels);
      if (vis) rec["noise_sigma"] = vis->noise_sigma;
      channels.push_back(labelChannel(label, ip.labels, "label" + suffix));
    }
    if (req.capture) {
      req.capture->keep(channels);
      if (d.tree) req.capture->warped.push_back(WarpedTree{profile.name, *d.tree, d.warp->describe()});
    }
    if (req.write_files) writeDegradedFiles(d, image, channels, forest, gt, profile.name, req, dir, files);
    if (d.tree) {
      std::int64_t mask_voxels = 0;
      for (auto m : d.labels->mask.data) mask_voxels += m;
      d.record["mask_voxels"] = mask_voxels;
    }
    degradation[profile.name] = d.record;
    if (seconds) (*seconds)[profile.name] = d.seconds;
  }
}

}  // namespace angiosynth
