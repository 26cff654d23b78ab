// `angiosynth segment`: a reference segmenter on an image (src/segment). Thin: options, the files,
// the summary line.
#include <iomanip>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "core/error.hpp"
#include "files/output_guard.hpp"
#include "io/nifti_reader.hpp"
#include "io/volume_writers.hpp"
#include "segment/segment.hpp"

namespace angiosynth::cli {

CLI::App* addSegment(CLI::App& app, SegmentArgs& a) {
  std::string methods;
  for (const auto& m : segmentMethods()) methods += std::string(methods.empty() ? "" : "; ") + m.name + ": " + m.summary;
  auto* c = app.add_subcommand("segment",
                               "segment an image (NIfTI) with a reference method, for baselines beside your own: a global threshold or "
                               "multiscale Hessian vesselness, thresholded; writes the mask on the image's grid");
  c->add_option("IMAGE", a.image, "the image (.nii or .nii.gz)")->required();
  c->add_option("--out", a.out, "the mask to write (.nii.gz; 1 vessel, 0 not)")->required();
  c->add_option("--method", a.options.method, "the method (default frangi): " + methods);
  c->add_option("--sigmas", a.options.sigmas_mm, "vesselness scales, Gaussian σ in mm (default 1, 2, 3 voxels)")->delimiter(',');
  c->add_flag("--dark", a.dark, "vessels darker than their surroundings (black-blood, inverted contrast)");
  c->add_option("--alpha", a.options.alpha, "Frangi's sensitivity to plate-like structure (default 0.5)");
  c->add_option("--beta", a.options.beta, "Frangi's sensitivity to blob-like structure (default 0.5)");
  c->add_option("--gamma", a.options.gamma,
                "Frangi's sensitivity to structure, on the scale-normalised Hessian's norm (default 15, as scikit-image; 0: half the largest norm, "
                "as Frangi et al. 1998)");
  c->add_option("--tau", a.options.tau, "Jerman's τ: the share of the largest eigenvalue that gives full response (default 0.75)");
  c->add_option("--threshold-fraction", a.options.threshold_fraction,
                "vesselness: the mask is the response at or above this share of its largest value (default 0.02)")
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--threshold", a.threshold, "an explicit threshold on the response (the image for otsu) instead of the rule");
  c->add_option("--response", a.response, "also write the response the mask thresholds (.nii.gz, float32)");
  c->add_flag("--force", a.force, "replace existing output files");
  addCommonOptions(*c, a.common);
  return c;
}

int runSegment(SegmentArgs a) {
  checkOutputFiles({{a.out, "--out"}, {a.response, "--response"}}, {a.image}, a.force);
  const auto threads = limitThreads(a.common.threads);
  a.options.bright = !a.dark;
  if (a.threshold) a.options.has_threshold = true, a.options.threshold = *a.threshold;
  NiftiVolume in = readNiftiVolume(a.image, memoryLimit(a.common), 4 + segmentBytesPerVoxel(a.options), "image");
  SegmentSummary s;
  Volume<float> response;
  Volume<std::uint8_t> mask;
  try {
    mask = segment(in.values, a.options, s, a.response.empty() ? nullptr : &response);
  } catch (const std::invalid_argument& e) { throw InputError("segment", 0, e.what()); }
  writeNiftiAtomically(a.out, viewOf(mask, true, "angiosynth segment " + s.method), &in.affine, a.force);
  if (!a.response.empty()) writeNiftiAtomically(a.response, viewOf(response, false, "angiosynth " + s.method + " response"), &in.affine, a.force);
  if (!a.common.quiet) {
    std::ostringstream scales;
    for (double v : s.sigmas_voxels) scales << (scales.tellp() > 0 ? "," : "") << std::setprecision(3) << v;
    std::cerr << "segment: " << s.method << (s.sigmas_voxels.empty() ? "" : ", σ " + scales.str() + " voxels") << ", threshold " << s.threshold
              << (s.method == "otsu" ? "" : " (largest response " + std::to_string(s.max_response) + ")") << ", " << s.voxels << " voxels, "
              << std::fixed << std::setprecision(2) << s.seconds << " s\n";
  }
  return 0;
}

}  // namespace angiosynth::cli
