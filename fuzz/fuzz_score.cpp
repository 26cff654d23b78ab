// Predictions as `score` reads them: the bytes as a NIfTI file (a gzip stream as .nii.gz, so
// truncated and corrupt streams are tried) scored against a small sample's truth (16^3 voxels,
// 24 terminals); odd sizes with TopCoW's conventions; sizes divisible by 3 against the sample's
// mask as a plain annotation under the TopCoW 2024 label scheme (the prediction's values as
// classes: per-class scores, detection, variants, topology matching).
#include <zlib.h>

#include "fuzz_support.hpp"
#include "config/scenario.hpp"
#include "pipeline/generate_sample.hpp"
#include "score/case_scores.hpp"
#include "score/label_schemes.hpp"

namespace {

const std::filesystem::path& sampleDir() {
  static const std::filesystem::path dir = [] {
    using namespace angiosynth;
    const auto root = fuzz::scratchDir();
    const auto map = root / "score_map16.txt";
    std::ofstream(map) << "16 16 16\n0 0 0 16 16 16\n1\n";
    const auto params = root / "score_sample.toml";
    std::ofstream(params) << "seed = 3\n[domain]\ndemand_map = \"" << map.string()
                          << "\"\nvoxel_size = \"1 mm\"\n[tree]\nterminals = 24\nroot_voxel = [0, 8, 8]\n"
                             "[physics]\nviscosity = \"3.6 mPa*s\"\nperfusion_pressure = \"13300 Pa\"\n"
                             "terminal_pressure = \"8300 Pa\"\nperfusion_flow = \"100 mm3/s\"\n"
                             "[image]\nformats = [\"nifti\"]\ngraph_formats = [\"csv\"]\n";
    const Scenario sc = readTomlParameters(params);
    const auto out = root / "score_sample";
    std::filesystem::remove_all(out);
    std::filesystem::create_directories(out);
    SampleRequest req;
    req.scenario = &sc;
    req.memory_limit = fuzz::kMemoryLimit;
    req.profiles = std::vector<Profile>{};
    generateSample(req, out);
    return out;
  }();
  return dir;
}

}  // namespace

// The sample's own mask, plain and compressed, joins the corpus (the last argument naming a directory):
// mutations of a prediction on the right grid reach past the header checks.
extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  for (int k = *argc - 1; k > 0; --k) {
    const std::filesystem::path corpus((*argv)[k]);
    if ((*argv)[k][0] == '-' || !std::filesystem::is_directory(corpus)) continue;
    std::filesystem::copy_file(sampleDir() / "mask.nii.gz", corpus / "sample_mask.nii.gz", std::filesystem::copy_options::overwrite_existing);
    if (gzFile g = gzopen((sampleDir() / "mask.nii.gz").c_str(), "rb")) {
      std::ofstream seed(corpus / "sample_mask.nii", std::ios::binary);
      char buf[65536];
      for (int n; (n = gzread(g, buf, sizeof buf)) > 0;) seed.write(buf, n);
      gzclose(g);
    }
    break;
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  ScoreOptions opt;
  opt.memory_limit = fuzz::kMemoryLimit;
  if (size % 2 == 1) opt.conventions = ScoreConventions::TopCoW;
  const bool plain = size % 3 == 0;
  if (plain) opt.scheme = labelScheme("topcow2024");
  const auto truth = plain ? annotationTruth(sampleDir() / "mask.nii.gz") : sampleTruth(sampleDir());
  // A gzip stream (its magic bytes first) is read as .nii.gz, truncated or corrupt as it comes.
  const bool gz = size >= 2 && data[0] == 0x1f && data[1] == 0x8b;
  const auto file = fuzz::writeInput(data, size, gz ? "pred.nii.gz" : "pred.nii");
  return fuzz::expectOnlyInputErrors([&] { scoreCase(file, truth, opt).toJson(); });
}
