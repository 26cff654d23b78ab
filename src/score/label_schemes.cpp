#include "score/label_schemes.hpp"

#include <fstream>

#include <nlohmann/json.hpp>

#include "core/error.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

LabelScheme topcow2024() {
  LabelScheme s;
  s.name = "topcow2024";
  s.source = "TopCoW 2024 evaluation (Yang et al. 2023): 13 Circle of Willis classes, values 13 and 14 unused";
  s.labels = {{1, "BA"},     {2, "R-PCA"},  {3, "L-PCA"}, {4, "R-ICA"},  {5, "R-MCA"},  {6, "L-ICA"},  {7, "L-MCA"},
              {8, "R-Pcom"}, {9, "L-Pcom"}, {10, "Acom"}, {11, "R-ACA"}, {12, "L-ACA"}, {15, "3rd-A2"}};
  s.detection_labels = {8, 9, 10, 15};
  s.detection_name = "group 2 (communicating arteries and the third A2)";
  s.missing_distance_mm = 90;  // about the largest distance in the Circle of Willis' region
  s.circle_of_willis = true;
  return s;
}

LabelScheme topbrain2025ct() {
  LabelScheme s;
  s.name = "topbrain2025-ct";
  s.source = "TopBrain 2025 evaluation, CTA track: 40 brain-vessel classes";
  const char* names[] = {"BA",     "R-P1P2", "L-P1P2", "R-ICA", "R-M1",   "L-ICA",  "L-M1",   "R-Pcom", "L-Pcom", "Acom",
                         "R-A1A2", "L-A1A2", "R-A3",   "L-A3",  "3rd-A2", "3rd-A3", "R-M2",   "R-M3",   "L-M2",   "L-M3",
                         "R-P3P4", "L-P3P4", "R-VA",   "L-VA",  "R-SCA",  "L-SCA",  "R-AICA", "L-AICA", "R-PICA", "L-PICA",
                         "R-AChA", "L-AChA", "R-OA",   "L-OA",  "VoG",    "StS",    "ICVs",   "R-BVR",  "L-BVR",  "SSS"};
  for (int v = 1; v <= 40; ++v) s.labels[v] = names[v - 1];
  s.detection_labels = {8, 9, 10, 15, 16, 25, 26, 27, 28, 29, 30, 31, 32, 33, 34, 37, 38, 39};
  s.detection_name = "side road";
  s.missing_distance_mm = 290;  // about the largest distance in a human head
  s.valid_neighbours = {{1, {2, 3, 23, 24, 25, 26, 27, 28, 29, 30}},
                        {2, {1, 4, 8, 11, 21, 25, 31, 38}},
                        {3, {1, 6, 9, 12, 22, 26, 32, 39}},
                        {4, {2, 5, 8, 11, 31}},
                        {5, {4, 17, 38}},
                        {6, {3, 7, 9, 12, 32}},
                        {7, {6, 19, 39}},
                        {8, {2, 4, 25, 31}},
                        {9, {3, 6, 26, 32}},
                        {10, {11, 12, 15}},
                        {11, {2, 4, 10, 12, 13, 14, 15, 16}},
                        {12, {3, 6, 10, 11, 13, 14, 15, 16}},
                        {13, {11, 12, 14, 15, 16}},
                        {14, {11, 12, 13, 15, 16}},
                        {15, {10, 11, 12, 13, 14, 16}},
                        {16, {11, 12, 13, 14, 15}},
                        {17, {5, 18}},
                        {18, {17}},
                        {19, {7, 20}},
                        {20, {19}},
                        {21, {2, 36, 37, 38}},
                        {22, {3, 36, 37, 39}},
                        {23, {1, 24, 27, 29}},
                        {24, {1, 23, 28, 30}},
                        {25, {1, 2, 8, 38}},
                        {26, {1, 3, 9, 39}},
                        {27, {1, 23, 29}},
                        {28, {1, 24, 30}},
                        {29, {1, 23, 27, 30}},
                        {30, {1, 24, 28, 29}},
                        {31, {2, 4, 8}},
                        {32, {3, 6, 9}},
                        {33, {}},
                        {34, {}},
                        {35, {36, 37, 38, 39}},
                        {36, {21, 22, 35}},
                        {37, {21, 22, 35, 38, 39}},
                        {38, {2, 5, 21, 25, 35, 37}},
                        {39, {3, 7, 22, 26, 35, 37}},
                        {40, {}}};
  return s;
}

int labelValue(const std::string& key, const std::string& file) {
  try {
    std::size_t used = 0;
    const int v = std::stoi(key, &used);
    if (used == key.size() && v > 0 && v < 256) return v;
  } catch (const std::exception&) {}
  throw InputError(file, 0, "label \"" + key + "\" is not a label value; allowed: whole numbers 1 to 255 as keys");
}

LabelScheme readScheme(const std::filesystem::path& file) {
  std::ifstream in(file);
  const Json j = Json::parse(in, nullptr, /*allow_exceptions=*/false);
  const std::string f = file.string();
  if (j.is_discarded() || !j.is_object() || !j.contains("labels") || !j["labels"].is_object())
    throw InputError(f, 0, "is not a label scheme; allowed: a JSON object with \"labels\": {\"1\": \"name\", …} (docs/scoring.md)");
  LabelScheme s;
  s.name = j.value("name", std::filesystem::path(file).stem().string());
  s.source = j.value("source", f);
  try {
    for (const auto& [k, v] : j["labels"].items()) s.labels[labelValue(k, f)] = v.get<std::string>();
    if (j.contains("detection_labels")) s.detection_labels = j["detection_labels"].get<std::vector<int>>();
    s.detection_name = j.value("detection_name", std::string("detection"));
    s.detection_iou = j.value("detection_iou", 0.25);
    s.missing_distance_mm = j.value("missing_distance_mm", 90.0);
    s.circle_of_willis = j.value("circle_of_willis", false);
    if (j.contains("valid_neighbours"))
      for (const auto& [k, v] : j["valid_neighbours"].items()) s.valid_neighbours[labelValue(k, f)] = v.get<std::vector<int>>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(f, 0, std::string("a field has the wrong type (") + e.what() + "); allowed: the fields of docs/scoring.md");
  }
  for (int v : s.detection_labels)
    if (!s.labels.count(v)) throw InputError(f, 0, "detection label " + std::to_string(v) + " is not among \"labels\"");
  if (!(s.detection_iou > 0 && s.detection_iou <= 1)) throw InputError(f, 0, "detection_iou must lie in (0, 1]");
  if (!(s.missing_distance_mm > 0)) throw InputError(f, 0, "missing_distance_mm must be a positive distance");
  return s;
}

}  // namespace

const std::vector<LabelScheme>& builtInLabelSchemes() {
  static const std::vector<LabelScheme> all{topcow2024(), topbrain2025ct()};
  return all;
}

LabelScheme labelScheme(const std::string& name) {
  for (const auto& s : builtInLabelSchemes())
    if (s.name == name) return s;
  if (std::filesystem::is_regular_file(name)) return readScheme(name);
  std::string allowed;
  for (const auto& s : builtInLabelSchemes()) allowed += (allowed.empty() ? "" : ", ") + s.name;
  throw InputError("", 0, "unknown label scheme \"" + name + "\"; allowed: " + allowed + ", or a JSON file of one (docs/scoring.md)");
}

}  // namespace angiosynth
