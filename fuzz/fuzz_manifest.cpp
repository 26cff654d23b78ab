// Dataset directories: a fuzzed manifest part beside a valid spec.json, through verify and finalize.
#include <nlohmann/json.hpp>

#include "dataset/run_dataset.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  const auto dir = fuzz::scratchDir() / "Dataset001_F";
  static const bool made = [&] {
    for (const char* sub : {"imagesTr", "labelsTr", "groundtruth/F_0000", "manifest"}) std::filesystem::create_directories(dir / sub);
    std::ofstream(dir / "spec.json") << nlohmann::json{{"name", "F"},           {"id", 1},          {"samples", 3}, {"seed", 1}, {"channel_name", ""},
                                                       {"spec_file", "f.toml"}, {"spec", "x = 1\n"}}
                                            .dump();
    std::ofstream(dir / "imagesTr" / "F_0000_0000.nii.gz") << "image";
    std::ofstream(dir / "groundtruth" / "F_0000" / "sample.json") << "{}";
    return true;
  }();
  (void)made;
  std::filesystem::remove(dir / "manifest.jsonl");
  fuzz::writeInput(data, size, "Dataset001_F/manifest/all.jsonl");
  return fuzz::expectOnlyInputErrors([&] {
    verifyDataset(dir);
    finalizeDataset(dir);
  });
}
