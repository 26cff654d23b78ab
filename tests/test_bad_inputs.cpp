// Every input kind refuses values that used to overflow, hang or allocate without an estimate:
// exit 2, `file:line: what is wrong, what is allowed`, and no output written.
#include <gtest/gtest.h>

#include <chrono>
#include <vector>

#include "cli_run.hpp"

namespace {

namespace fs = std::filesystem;

struct BadCase {
  const char* name;
  const char* file;  // written into the test directory, from the base text of `base`
  const char* base;  // "toml", "vs" (VascuSynth parameters), "spec" (dataset spec), "" (text below as is)
  const char* from;  // replaced in the base text ("" : append `to`)
  const char* to;
  const char* args;    // the command line; its output goes to out/
  const char* expect;  // a piece of the first line of stderr, file:line included where there is one
};

const BadCase kCases[] = {
    {"root_nan", "p.toml", "toml", "root_voxel = [0, 50, 50]", "root_voxel = [nan, 50, 50]", "generate p.toml --out out",
     "p.toml:14: root_voxel must hold finite numbers only"},
    {"background_nan", "p.toml", "toml", "[output]", "[image]\nbackground = nan\n[output]", "generate p.toml --out out",
     "p.toml:31: background must be a finite number"},
    {"supply_cutoff_huge", "p.toml", "toml", "[0.65, 0.34, 0.01, 7]", "[0.65, 0.34, 0.01, 1e300]", "generate p.toml --out out",
     "p.toml:8: supply_coefficients: the last value is the cut-off radius (map voxels); allowed: 0 to 1e6"},
    {"fov_huge", "p.toml", "toml", "[output]", "[image]\nfield_of_view = [\"1e300 mm\", \"1 mm\", \"1 mm\"]\n[output]", "generate p.toml --out out",
     "p.toml:31: field_of_view entry = 1e+300 is out of range; allowed: (0, 1e+06] mm"},
    {"fov_too_many_voxels", "p.toml", "toml", "[output]", "[image]\nvoxel_size = \"0.0001 mm\"\nformats = [\"vdb\"]\n[output]",
     "generate p.toml --out out --no-profiles", "p.toml:30: the image would be 400000 voxels along one axis"},
    {"closest_neighbours_wraps", "p.toml", "toml", "closest_neighbours = 5", "closest_neighbours = 4294967301", "generate p.toml --out out",
     "p.toml:16: closest_neighbours = 4294967301 is out of range; allowed: [1, 100]"},
    {"flow_1000x", "p.toml", "toml", "8330 mm3/s", "8330000 mm3/s", "generate p.toml --out out", "p.toml:13: vessels too thick for the domain"},
    {"terminals_5M_on_100cubed", "p.toml", "toml", "terminals = 60", "terminals = 5000000", "generate p.toml --out out",
     "p.toml:13: 5000000 terminals cannot lie 0.4 mm apart"},
    {"voxel_width_tiny", "p.txt", "vs", "VOXEL_WIDTH: 0.04", "VOXEL_WIDTH: 1e-12", "generate p.txt --out out",
     "p.txt:14: VOXEL_WIDTH (cm) = 1e-12 is out of range"},
    {"rho_huge", "p.txt", "vs", "RHO: 0.036", "RHO: 1e300", "generate p.txt --out out", "p.txt:8: RHO (g/(cm*s)) = 1e+300 is out of range"},
    {"flow_huge", "p.txt", "vs", "PERF_FLOW: 8.33", "PERF_FLOW: 1e300", "generate p.txt --out out",
     "p.txt:7: PERF_FLOW (cm^3/s) = 1e+300 is out of range"},
    {"min_distance_huge", "p.txt", "vs", "MIN_DISTANCE: 1", "MIN_DISTANCE: 1e300", "generate p.txt --out out",
     "p.txt:12: MIN_DISTANCE (map voxels) = 1e+300 is out of range"},
// Forests of method cco: [[tree.inlet]] tables.
#define CCO_FOREST "[domain]\nshape = \"sphere\"\nradius = \"10 mm\"\nvoxel_size = \"0.5 mm\"\n[tree]\nmethod = \"cco\"\nterminals = 100\n"
    {"inlet_shares_sum", "p.toml", "", "",
     CCO_FOREST "[[tree.inlet]]\nroot_offset = [0, 10, 0]\nshare = 0.5\n[[tree.inlet]]\nroot_offset = [0, -10, 0]\nshare = 0.4\n",
     "generate p.toml --out out", "p.toml:11: the shares of the artery inlets sum to 0.9; fixed shares of one kind must sum to 1"},
    {"inlet_vein_supplies", "p.toml", "", "",
     CCO_FOREST "[[tree.inlet]]\nroot_offset = [0, 10, 0]\n[[tree.inlet]]\nkind = \"vein\"\nroot_offset = [0, -10, 0]\nroot_pressure = \"30 "
                "mmHg\"\nterminal_pressure = \"20 mmHg\"\n",
     "generate p.toml --out out", "p.toml:13: inlet 'vein' is a vein: it drains, so its terminal_pressure must exceed its root_pressure"},
    {"inlet_duplicate_id", "p.toml", "", "",
     CCO_FOREST "[[tree.inlet]]\nid = \"a\"\nroot_offset = [0, 10, 0]\n[[tree.inlet]]\nid = \"a\"\nroot_offset = [0, -10, 0]\n",
     "generate p.toml --out out", "p.toml:12: a second inlet with id 'a'; ids must be unique"},
    {"inlet_without_root", "p.toml", "", "", CCO_FOREST "[[tree.inlet]]\nroot_offset = [0, 10, 0]\n[[tree.inlet]]\nkind = \"vein\"\n",
     "generate p.toml --out out", "p.toml:10: missing key 'root_offset' (mm from the centre) in [[tree.inlet]]"},
    {"inlet_roots_touch", "p.toml", "", "", CCO_FOREST "[[tree.inlet]]\nroot_offset = [0, 10, 0]\n[[tree.inlet]]\nroot_offset = [0.1, 9.99, 0]\n",
     "generate p.toml --out out", "p.toml:11: the roots of inlets 'artery_1' and 'artery_2' lie 0.100499 mm apart"},
    {"murray_bands_count", "p.toml", "", "", CCO_FOREST "[physics]\nmurray_band_edges = [\"0.1 mm\", \"1 mm\"]\nmurray_band_exponents = [3, 2.5]\n",
     "generate p.toml --out out",
     "p.toml:10: murray_band_exponents holds 2 exponents for 2 murray_band_edges; allowed: one exponent more than edges"},
    {"murray_bands_close", "p.toml", "", "",
     CCO_FOREST "[physics]\nmurray_band_edges = [\"0.1 mm\", \"0.11 mm\"]\nmurray_band_exponents = [3, 2.7, 2.3]\n", "generate p.toml --out out",
     "p.toml:9: murray_band_edges 0.1 mm and 0.11 mm: allowed: ascending, each edge at least 1.25 times the one before (an edge ramps γ over ±5 % of "
     "its radius)"},
#undef CCO_FOREST
// dcco growing from an existing network ([initial]).
#define DCCO_INITIAL \
  "[domain]\nshape = \"disc\"\nradius = \"20 mm\"\nvoxel_size = \"0.1 mm\"\n[tree]\nmethod = \"dcco\"\n[[stage]]\nterminals = 10\n[initial]\n"
    {"initial_origin_unknown", "p.toml", "", "",
     DCCO_INITIAL "file = \"" ANGIOSYNTH_SOURCE_DIR "/examples/dcco_outlet_t0_2d.swc\"\norigin = \"middle\"\n", "generate p.toml --out out",
     "p.toml:11: origin 'middle'; allowed: centre, corner"},
    {"initial_format_unknown", "p.toml", "", "", DCCO_INITIAL "file = \"p.toml\"\n", "generate p.toml --out out",
     "p.toml: unknown network format '.toml'; allowed: .cco (VItA), .swc, .gxl, .csv (nodes and edges), .vtp"},
    {"initial_unit_unknown", "p.toml", "", "",
     DCCO_INITIAL "file = \"" ANGIOSYNTH_SOURCE_DIR "/tests/data/network/tree_ascii.vtp\"\nunit = \"inch\"\n", "generate p.toml --out out",
     "p.toml:11: unit 'inch'; allowed: mm, cm, m, um"},
#undef DCCO_INITIAL
// Space colonisation.
#define COLONISATION "[domain]\nshape = \"disc\"\nradius = \"10 mm\"\nvoxel_size = \"0.1 mm\"\n[tree]\nmethod = \"colonisation\"\n"
    {"colonisation_kappa_4_5", "p.toml", "", "", COLONISATION "[physics]\nmurray_exponent = 4.5\n", "generate p.toml --out out",
     "p.toml:8: murray_exponent = 4.5 is out of range; allowed: (2, 4)"},
    {"colonisation_no_vein_root", "p.toml", "", "", COLONISATION "[[tree.inlet]]\nkind = \"artery\"\nroot_offset = [0, 9]\n",
     "generate p.toml --out out", "p.toml:7: no vein root: add a [[tree.inlet]] with kind = \"vein\", or set [tree] veins = false"},
#undef COLONISATION
// L-system (Lázaro 2011): blocks the inverse problem cannot fill.
#define LZH                                                                                                             \
  "[domain]\nvoxel_size = \"0.1 mm\"\n[tree]\nmethod = \"lsystem\"\nblock_width = \"10 mm\"\nstart_length = \"3 mm\"\n" \
  "capillary_length = \"2 mm\"\nstart_diameter = \"1 mm\"\ncapillary_diameter = \"0.2 mm\"\ncapillary_spacing = \"1.2 mm\"\n"
    {"lzh_block_too_low", "p.toml", "", "", LZH "block_height = \"7 mm\"\n", "generate p.toml --out out",
     "p.toml:11: block_height 7 mm leaves no room for the trees: it must exceed 2·start_length + capillary_length = 8 mm"},
    {"lzh_capillary_walls_overlap", "p.toml", "", "", LZH "block_height = \"20 mm\"\ncapillary_wall = \"0.3 mm\"\n", "generate p.toml --out out",
     "p.toml:10: neighbouring capillaries lie 0.586667 mm apart, less than their outer diameter 0.8 mm"},
    {"lzh_unknown_mode", "p.toml", "", "", LZH "block_height = \"20 mm\"\nmode = \"vsystem\"\n", "generate p.toml --out out",
     "p.toml:12: mode 'vsystem'; allowed: lzh, grammar"},
    {"grammar_with_lzh_key", "p.toml", "", "", LZH "mode = \"grammar\"\n", "generate p.toml --out out",
     "p.toml:5: 'block_width' in [tree] is for mode lzh; this file's mode is grammar ([tree] mode)"},
    // Curved vessels: an unbounded target, two wavelengths, an unknown key.
    {"curves_tortuosity_below_one", "p.toml", "", "", LZH "block_height = \"20 mm\"\n[curves]\ntortuosity = 0.9\n", "generate p.toml --out out",
     "p.toml:13: tortuosity = 0.9 is out of range; allowed: [1, 3]"},
    {"curves_two_wavelengths", "p.toml", "", "", LZH "block_height = \"20 mm\"\n[curves]\nwavelength = \"2 mm\"\nwavelength_radii = 30\n",
     "generate p.toml --out out", "p.toml:14: give wavelength (a length) or wavelength_radii (multiples of each vessel's radius), not both"},
    {"curves_unknown_key", "p.toml", "", "", LZH "block_height = \"20 mm\"\n[curves]\namplitude = 2\n", "generate p.toml --out out",
     "p.toml:13: unknown key 'amplitude'"},
#undef LZH
    {"profile_intensity_huge", "prof.toml", "", "", "background = 1e30\n[[effect]]\ntype = \"gaussian\"\nsigma = 1\n",
     "generate p.toml --out out --profile prof.toml", "prof.toml:1: background = 1e+30 is out of range"},
    {"bias_scale_tiny", "prof.toml", "", "", "[[effect]]\ntype = \"bias\"\namplitude = 0.2\nscale = \"1e-9 mm\"\n",
     "generate p.toml --out out --profile prof.toml", "prof.toml:4: scale = 1e-09 mm is finer than 1 voxel"},
    {"blur_sigma_huge", "prof.toml", "", "", "[[effect]]\ntype = \"blur\"\nsigma = \"1e6 mm\"\n", "generate p.toml --out out --profile prof.toml",
     "prof.toml:3: sigma = 1e+06 mm exceeds 1 fov"},
    {"shadows_million", "prof.toml", "", "", "[[effect]]\ntype = \"shadow\"\ncount = 1000000\n", "generate p.toml --out out --profile prof.toml",
     "prof.toml:3: count = 1e+06 is out of range; allowed: [0, 1000]"},
    {"spec_integer_int64_max", "s.toml", "spec", "terminals = {integer = [60, 160]}",
     "terminals = {integer = [9223372036854775807, 9223372036854775807]}", "dataset s.toml --out out",
     "s.toml:15: integer takes whole numbers [a, b] with a <= b, each within ±2^53"},
    {"spec_misspelt_distribution", "s.toml", "spec", "terminals = {integer = [60, 160]}", "terminals = {unifrom = [60, 160]}",
     "dataset s.toml --out out", "s.toml:15: unknown key 'unifrom' in a distribution; allowed: uniform"},
    {"spec_draw_out_of_range_names_its_line", "s.toml", "spec", "terminals = {integer = [60, 160]}", "terminals = {uniform = [60, 160]}",
     "dataset s.toml --out out", "s.toml:15: terminals must be a whole number"},
    {"dataset_index_int64_max", "s.toml", "spec", "", "", "dataset s.toml --out out --index 9223372036854775807",
     "--index 9223372036854775807 is beyond the dataset's 6 samples"},
    // Label policies ([image] label_policy and its parameters), in parameter files and specs.
    {"label_policy_unknown", "p.toml", "toml", "[output]", "[image]\nlabel_policy = \"fuzzy\"\n[output]", "generate p.toml --out out",
     "p.toml:31: label_policy 'fuzzy' is not allowed; allowed: binary, threshold, visible, soft, ignore"},
    {"label_threshold_of_another_policy", "p.toml", "toml", "[output]", "[image]\nlabel_policy = \"visible\"\nlabel_threshold = 0.3\n[output]",
     "generate p.toml --out out", "p.toml:32: label_threshold is a parameter of label_policy = \"threshold\", not of \"visible\""},
    {"label_threshold_zero", "p.toml", "toml", "[output]", "[image]\nlabel_policy = \"threshold\"\nlabel_threshold = 0\n[output]",
     "generate p.toml --out out", "p.toml:32: label_threshold = 0 is out of range; allowed: (0, 1]"},
    {"ignore_band_reversed", "p.toml", "toml", "[output]", "[image]\nlabel_policy = \"ignore\"\nignore_band = [0.8, 0.2]\n[output]",
     "generate p.toml --out out", "p.toml:32: ignore_band = [0.8, 0.2]; allowed: [low, high] partial volumes with 0 <= low < high <= 1"},
    {"spec_label_policy_drawn", "s.toml", "spec", "supersampling = 2", "supersampling = 2\nlabel_policy = {choice = [\"binary\", \"ignore\"]}",
     "dataset s.toml --out out", "s.toml:28: label_policy must be one policy for the whole dataset"},
    {"params_is_a_directory", "d/x", "", "", "", "generate d --out out", "d: is a directory; give a parameter file"},
    {"usage_error", "x", "", "", "", "generate --out out", "PARAMS is required"},
    {"cli_memory_limit_nan", "x", "", "", "", "generate p.toml --out out --memory-limit nan",
     "--memory-limit: 'nan' is not a finite number in [0, 1e+06]"},
    {"cli_seed_negative", "x", "", "", "", "generate p.toml --out out --seed -1", "--seed: Value -1 not in range 0 to 9223372036854775807"},
    {"cli_voxel_width_nan", "x", "", "", "", "vascusynth list.txt names.txt nan", "VOXEL_WIDTH: 'nan' is not a finite number"},
};

class BadInput : public ::testing::TestWithParam<BadCase> {
 protected:
  void SetUp() override { dir_ = freshTestDir("angiosynth_bad_"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  const fs::path src_ = ANGIOSYNTH_SOURCE_DIR;
};

std::string baseText(const std::string& kind, const fs::path& src) {
  std::string t;
  if (kind == "toml") {
    t = selfContained(src / "examples/vascusynth_like.toml");
    replaceOnce(t, "terminals = 1000", "terminals = 60");
  } else if (kind == "vs") {
    t = selfContained(src / "examples/vascusynth/param_rods_1000.txt");
  } else if (kind == "spec") {
    t = selfContained(src / "tests/data/dataset_tiny.toml");
  }
  return t;
}

TEST_P(BadInput, ExitsTwoNamingFileAndLineAndWritesNothing) {
  const BadCase& c = GetParam();
  // The plain parameter file every profile case uses.
  std::string p = baseText("toml", src_);
  replaceOnce(p, "profiles = [\"vascusynth\", \"cta\"]", "profiles = []");
  std::ofstream(dir_ / "p.toml") << p;
  std::string text = baseText(c.base, src_);
  if (std::string(c.from).empty())
    text += c.to;
  else
    replaceOnce(text, c.from, c.to);
  fs::create_directories((dir_ / c.file).parent_path());
  std::ofstream(dir_ / c.file) << text;
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = run(c.args, dir_);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out")) << c.name;
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_EQ(e.path().filename().string().find(".out.tmp"), std::string::npos);
  RecordProperty("seconds", std::to_string(seconds));
}

INSTANTIATE_TEST_SUITE_P(Inputs, BadInput, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<BadCase>& i) { return std::string(i.param.name); });

TEST(BadInputFiles, NiftiMaskWithMicroscopicVoxelsAndDamagedDatasetsAreInputErrors) {
  const fs::path dir = freshTestDir("angiosynth_badnii_");
  const fs::path src = ANGIOSYNTH_SOURCE_DIR;
  // An 8^3 ball with pixdim 1e-9 mm, written by nibabel.
  const std::string py =
      "/usr/bin/python3 -c \"import numpy as np, nibabel as nib; i,j,k = np.mgrid[:8,:8,:8]; "
      "m = (((i-3.5)**2+(j-3.5)**2+(k-3.5)**2) < 12).astype(np.uint8); "
      "nib.save(nib.Nifti1Image(m, np.diag([1e-9, 1e-9, 1e-9, 1])), '" +
      (dir / "m.nii").string() + "')\"";
  ASSERT_EQ(std::system(py.c_str()), 0);
  std::ofstream(dir / "p.toml") << "[domain]\nshape = \"mask\"\nmask = \"m.nii\"\n[tree]\nmethod = \"cco\"\nterminals = 10\n"
                                   "root_voxel = [4, 4, 4]\n";
  auto r = run("generate p.toml --out out", dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("m.nii: voxel size 1e-09 mm (pixdim) is out of range"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
  // Dimensions 5 to 7 count too (fuzzing found a header whose dim[6], dim[7] made the library
  // read 2 GB past the 3D memory estimate).
  const std::string py7 =
      "/usr/bin/python3 -c \"import numpy as np, nibabel as nib; "
      "nib.save(nib.Nifti1Image(np.ones((8, 8, 8, 1, 1, 1, 3), np.uint8), np.eye(4)), '" +
      (dir / "m.nii").string() + "')\"";
  ASSERT_EQ(std::system(py7.c_str()), 0);
  r = run("generate p.toml --out out", dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("m.nii: a mask must be one 3D (or one-slice 2D) volume; this one has dims 8 8 8 1 1 1 3"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
  // A dataset directory without imagesTr/: a problem verify reports, not an internal error.
  std::ofstream(dir / "s.toml") << selfContained(src / "tests/data/dataset_tiny.toml");
  ASSERT_EQ(run("dataset s.toml --out raw --quiet", dir).code, 0);
  fs::remove_all(dir / "raw/Dataset902_VesselTiny/imagesTr");
  r = run("dataset verify raw/Dataset902_VesselTiny", dir);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("missing directory imagesTr/"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

}  // namespace
