// Hostile inputs to what came after the first fuzzing campaign: graph files for `mesh` and for
// [initial], mesh options, the newer methods' parameters, score, init and plot-calibre. Each test
// is one defect that was seen: a lost file, a crash, a hang or nonsense with exit 0.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <regex>

#include "cli_run.hpp"
#include "core/error.hpp"
#include "core/physical_ranges.hpp"
#include "core/segment_grid.hpp"
#include "core/interrupt_cleanup.hpp"
#include "files/atomic_file.hpp"
#include "io/network_files.hpp"
#include "io/nifti_reader.hpp"
#include "files/staged_directory.hpp"
#include "mesh/tube_surface.hpp"
#include "grow_file.hpp"
#include "test_support.hpp"

using namespace angiosynth;

namespace {

namespace fs = std::filesystem;

class Robustness : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = freshTestDir("angiosynth_robust_"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  // The InputError readNetwork throws, or "" if it reads the file.
  std::string networkError(const std::string& name, const std::string& text, std::uint64_t limit = 0) const {
    const auto file = write(name, text);
    try {
      readNetwork(file, 1, limit);
    } catch (const InputError& e) { return e.what(); }
    return "";
  }
  // A two-vessel SWC: a root sample, a bifurcation-free chain of `samples` along x.
  fs::path swc(const std::string& name, const std::string& rows) const { return write(name, rows); }
  fs::path dir_;
};

// A DCCO file continuing `network` in a 2D disc (radius 20 mm), 20 terminals.
std::string dccoWithInitial(const std::string& network, const std::string& extra = "") {
  return "seed = 1\n[domain]\nshape = \"disc\"\nradius = \"20 mm\"\nvoxel_size = \"0.1 mm\"\n[tree]\nmethod = \"dcco\"\n"
         "root_radius = \"0.2 mm\"\n[initial]\nfile = \"" +
         network + "\"\nbranching = \"versatile\"\nrole = \"distribution\"\n" + extra +
         "[physics]\nperfusion_flow = \"0.33 mL/min\"\n[[stage]]\nterminals = 20\n[image]\nformats = []\n";
}

// The names in a directory, sorted, one a line.
std::string files(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  std::string out;
  for (const auto& n : names) out += n + "\n";
  return out;
}

// ---- Files lost ------------------------------------------------------------------------------

TEST_F(Robustness, InitLeavesAFileOrLinkNamedLikeItsTemporaryAlone) {
  write("p.toml.tmp-angiosynth", "the user's own notes\n");
  write("target.txt", "a file a link points to\n");
  fs::create_symlink(dir_ / "target.txt", dir_ / "q.toml.tmp-angiosynth");
  ASSERT_EQ(run("init cco p.toml", dir_).code, 0);
  ASSERT_EQ(run("init cco q.toml", dir_).code, 0);
  EXPECT_EQ(slurp(dir_ / "p.toml.tmp-angiosynth"), "the user's own notes\n");
  EXPECT_EQ(slurp(dir_ / "target.txt"), "a file a link points to\n");
  EXPECT_TRUE(fs::is_symlink(dir_ / "q.toml.tmp-angiosynth"));
  EXPECT_NE(slurp(dir_ / "p.toml").find("[tree]"), std::string::npos);
  // An existing template is never replaced.
  write("mine.toml", "seed = 1\n");
  EXPECT_EQ(run("init cco mine.toml", dir_).code, 2);
  EXPECT_EQ(slurp(dir_ / "mine.toml"), "seed = 1\n");
}

TEST_F(Robustness, InitWithAnEmptyOrDirectoryNameIsRefusedAndLeavesNothing) {
  const std::string before = files(dir_);
  for (const char* name : {"\"\"", "sub/", "."}) {
    fs::create_directories(dir_ / "sub");
    const auto r = run(std::string("init cco ") + name, dir_);
    EXPECT_EQ(r.code, 2) << name << ": " << r.err;
    EXPECT_NE(r.err.find("is not a file name"), std::string::npos) << r.err;
  }
  fs::remove(dir_ / "sub");
  EXPECT_EQ(files(dir_), before + "stderr.txt\n");
}

TEST_F(Robustness, AtomicFilesAreCreatedExclusivelyAndLeaveNoTemporary) {
  write("kept.txt", "old\n");
  writeFileAtomically(dir_ / "kept.txt", "new\n");
  EXPECT_EQ(slurp(dir_ / "kept.txt"), "new\n");
  EXPECT_THROW(writeFileAtomically(dir_ / "kept.txt", "newer\n", /*replace=*/false), InputError);
  EXPECT_EQ(slurp(dir_ / "kept.txt"), "new\n");
  EXPECT_THROW(writeFileAtomically(dir_ / "no_such_dir" / "x.json", "{}"), InputError);
  EXPECT_EQ(files(dir_), "kept.txt\n");
}

// A SIGKILL leaves an AtomicFile's temporary behind (a killed dataset run left manifest.jsonl's):
// the next writer of that file, or a dataset run in that directory, removes those of processes
// that are gone, and nothing else.
TEST_F(Robustness, TemporariesOfKilledProcessesAreRemovedAndNoOtherFile) {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ::waitpid(child, nullptr, 0);
  const std::string self = stagingSuffix();
  const std::string host = self.substr(0, self.rfind('-'));
  const std::string gone = host + "-" + std::to_string(child) + "-0123456789abcdef";
  write(".kept.txt.tmp-angiosynth-" + gone, "killed\n");
  write(".other.txt.tmp-angiosynth-" + gone, "killed\n");
  write(".kept.txt.tmp-angiosynth-" + self + "-0123456789abcdef", "this process is writing it\n");
  write(".kept.txt.tmp-angiosynth-elsewhere-1-0123456789abcdef", "another machine may still be writing it\n");
  write(".kept.txt.tmp-angiosynth-notes", "the user's own\n");
  write("target.txt", "a file a link points to\n");
  fs::create_symlink(dir_ / "target.txt", dir_ / (".link.txt.tmp-angiosynth-" + gone));
  writeFileAtomically(dir_ / "kept.txt", "new\n");
  EXPECT_FALSE(fs::exists(dir_ / (".kept.txt.tmp-angiosynth-" + gone)));
  EXPECT_TRUE(fs::exists(dir_ / (".other.txt.tmp-angiosynth-" + gone))) << "only the temporaries of the file written";
  EXPECT_EQ(removeAbandonedTemporaries(dir_), 1);
  for (const std::string& kept :
       {".kept.txt.tmp-angiosynth-" + self + "-0123456789abcdef", std::string(".kept.txt.tmp-angiosynth-elsewhere-1-0123456789abcdef"),
        std::string(".kept.txt.tmp-angiosynth-notes"), ".link.txt.tmp-angiosynth-" + gone, std::string("kept.txt"), std::string("target.txt")})
    EXPECT_TRUE(fs::exists(fs::symlink_status(dir_ / kept))) << kept;
  EXPECT_FALSE(fs::exists(dir_ / (".other.txt.tmp-angiosynth-" + gone)));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 6);
}

TEST_F(Robustness, PlotCalibreNeverWritesOverItsInput) {
  const std::string scores = R"({"calibre": [{"radius_voxels": [0, 1], "recall": 0.5}, {"radius_voxels": [1, 2], "recall": 0.75}]})";
  write("s.json", scores);
  const auto r = run("plot-calibre s.json s.json --force", dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(slurp(dir_ / "s.json"), scores);
  EXPECT_EQ(run("plot-calibre plot.png s.json", dir_).code, 0);
  EXPECT_EQ(slurp(dir_ / "plot.png").substr(1, 3), "PNG");
}

TEST_F(Robustness, ScoreRefusesOneFileForTwoOutputs) {
  // The outputs are checked before the inputs are read: any paths show it.
  for (const std::string outputs : {"--out x --csv x", "--out x --plot x", "--csv y --plot ./y"}) {
    const auto r = run("score pred.nii.gz sample " + outputs, dir_);
    EXPECT_EQ(r.code, 2) << outputs;
    EXPECT_NE(r.err.find("a file of its own for each output"), std::string::npos) << outputs << ": " << r.err;
  }
}

TEST_F(Robustness, MeshWritesBesideASampleGivenWithATrailingSlash) {
  fs::create_directories(dir_ / "sample");
  std::ofstream(dir_ / "sample" / "nodes.csv") << "id,pos_x,pos_y,pos_z\n0,0,0,0\n1,4,0,0\n";
  std::ofstream(dir_ / "sample" / "edges.csv") << "id,node1id,node2id,radius\n1,0,1,0.5\n";
  const auto r = run("mesh sample/ --quiet", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "sample_mesh" / "surface.stl"));
  EXPECT_FALSE(fs::exists(dir_ / "sample" / "_mesh"));
  EXPECT_EQ(files(dir_ / "sample"), "edges.csv\nnodes.csv\n");
}

TEST_F(Robustness, StagingLeavesADirectoryOfItsNameThatItDidNotMakeAlone) {
  // The staging name of this process, made by somebody else (no marker inside).
  const fs::path out = dir_ / "out";
  const fs::path squatter = dir_ / (".out.tmp-" + stagingSuffix());
  fs::create_directories(squatter);
  std::ofstream(squatter / "keep.txt") << "not angiosynth's\n";
  {
    StagedDirectory d(out, ExistingOutput::Refuse, {});
    EXPECT_NE(d.path(), squatter);
    std::ofstream(d.path() / "a.txt") << "a\n";
    d.commit();
  }
  EXPECT_EQ(slurp(squatter / "keep.txt"), "not angiosynth's\n");
  EXPECT_TRUE(fs::exists(out / "a.txt"));
}

// ---- Crashes and internal errors -------------------------------------------------------------

TEST_F(Robustness, PlotCalibreRefusesScoresOfAnotherShape) {
  for (const std::string json : {R"({"calibre":[{}]})", R"({"per_case":[{}]})", R"({"calibre":"x"})",
                                 R"({"calibre":[{"radius_voxels":"a","recall":1}]})", R"({"calibre":[{"radius_voxels":[1],"recall":"high"}]})",
                                 R"({"calibre":[{"radius_voxels":[2],"recall":1},{"radius_voxels":[1],"recall":1}]})",
                                 R"({"per_case":[{"calibre":[{"radius_voxels":[0],"recall":1}]},{"calibre":[{"radius_voxels":[1],"recall":1}]}]})",
                                 R"({"per_case":7})", R"([1,2])"}) {
    write("bad.json", json);
    const auto r = run("plot-calibre out.png bad.json --force", dir_);
    EXPECT_EQ(r.code, 2) << json << ": " << r.err;
    EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
}

TEST_F(Robustness, EveryGraphReaderHoldsValuesToThePhysicalRanges) {
  const std::string gxl_head = R"(<?xml version="1.0"?><gxl><graph id="t">)";
  const auto gxl = [&](const std::string& x, const std::string& radius) {
    return gxl_head + R"(<node id="a"><attr name="position"><tup><float>0</float><float>0</float><float>0</float></tup></attr></node>)" +
           R"(<node id="b"><attr name="position"><tup><float>)" + x + R"(</float><float>0</float><float>0</float></tup></attr></node>)" +
           R"(<edge from="a" to="b"><attr name="radius"><float>)" + radius + "</float></attr></edge></graph></gxl>";
  };
  const auto vtp = [](const std::string& x, const std::string& radius) {
    return "<?xml version=\"1.0\"?><VTKFile type=\"PolyData\" byte_order=\"LittleEndian\"><PolyData><Piece NumberOfPoints=\"2\" "
           "NumberOfLines=\"1\"><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0 " +
           x + " 0 0</DataArray></Points><CellData><DataArray type=\"Float64\" Name=\"Radius\" format=\"ascii\">" + radius +
           "</DataArray></CellData><Lines><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1</DataArray><DataArray "
           "type=\"Int64\" Name=\"offsets\" format=\"ascii\">2</DataArray></Lines></Piece></PolyData></VTKFile>";
  };
  const auto cco = [](const std::string& x, const std::string& radius) {
    return "*Tree\n0 0 0 1 0 1 1 1 2 0.1 1e-6\n*Vessels\n1\n0 0 0 0 " + x + " 0 0 0 0 0 0 0 " + radius + " 0 0 0 0 0 0 0\n*Connectivity\n0 -1\n";
  };
  write("t_edges.csv", "id,node1id,node2id,radius\n0,0,1,1e300\n");
  for (const auto& [name, text, why] :
       std::vector<std::tuple<std::string, std::string, std::string>>{{"r.swc", "1 1 0 0 0 1e300 -1\n2 3 1 0 0 1e300 1\n", "radius"},
                                                                      {"c.swc", "1 1 0 0 0 0.1 -1\n2 3 1e300 0 0 0.1 1\n", "coordinate"},
                                                                      {"r.gxl", gxl("1", "1e300"), "radius"},
                                                                      {"c.gxl", gxl("1e300", "0.1"), "coordinate"},
                                                                      {"t_nodes.csv", "id,pos_x,pos_y,pos_z\n0,0,0,0\n1,1,0,0\n", "radius"},
                                                                      {"r.vtp", vtp("1", "1e155"), "radius"},
                                                                      {"c.vtp", vtp("1e300", "0.1"), "coordinate"},
                                                                      {"r.cco", cco("1", "-0.5"), "radius"},
                                                                      {"c.cco", cco("1e300", "0.1"), "coordinate"},
                                                                      {"one.swc", "1 1 0 0 0 0.1 -1\n", "no vessel"}}) {
    const auto e = networkError(name, text);
    EXPECT_NE(e.find(why), std::string::npos) << name << ": " << e;
    EXPECT_NE(e.find("allowed"), std::string::npos) << name << ": " << e;
  }
  // A node of many children: read (as NetworkFiles tests), refused up front by what walks its
  // links for each of its vessels: growth from it (over a minute at 2000) and meshing.
  std::string star = "1 1 0 0 0 0.2 -1\n2 3 0 1 0 0.2 1\n";
  for (int k = 0; k < 2000; ++k)
    star += std::to_string(k + 3) + " 3 " + std::to_string(std::cos(k * 0.00314) * 3) + " " + std::to_string(1 + std::sin(k * 0.00314) * 3) +
            " 0 0.05 2\n";
  write("star.swc", star);
  write("star.toml", dccoWithInitial("star.swc"));
  for (const std::string command : {"generate star.toml --out o --no-image", "mesh star.swc --out m"}) {
    const auto r = run(command, dir_);
    EXPECT_EQ(r.code, 2) << command;
    EXPECT_NE(r.err.find("star.swc:2: node 2 has 2000 children"), std::string::npos) << command << ": " << r.err;
  }
}

TEST(RobustnessFiles, AJunctionsLinksAreReadWhereverTheNodesArrayMoves) {
  // A link was added at its junction's position by reference, which the push_back of the link
  // itself could move (heap-use-after-free under the sanitizers; found by fuzz_graph_mesh).
  const auto net = readNetwork(test::sourceDir() / "fuzz/regressions/fuzz_graph_mesh/junction-link-position-moved.swc");
  const auto& t = net.tree;
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    if (t.isLink(i)) { EXPECT_EQ(t.length[i], 0.0) << "link " << i; }
  }
  EXPECT_EQ(t.roots().size(), 1u);
}

TEST_F(Robustness, ClipBoxesAreBoundedAndBeyondTheSurfaceCutNothing) {
  write("v.swc", "1 1 0 0 0 0.5 -1\n2 3 20 0 0 0.5 1\n");
  const auto volume = [&](const std::string& box) {
    const auto r = run("mesh v.swc --out m --force --quiet --clip-box=" + box, dir_);
    EXPECT_EQ(r.code, 0) << box << ": " << r.err;
    std::ifstream in(dir_ / "m" / "mesh.json");
    const auto j = nlohmann::json::parse(in);
    return j["statistics"]["enclosed_volume_mm3"].get<double>();
  };
  const double tight = volume("5,-10,-10,30,10,10"), wide = volume("5,-1e6,-1e6,1e6,1e6,1e6");
  EXPECT_NEAR(tight, std::numbers::pi * 0.25 * 15 + 2.0 / 3 * std::numbers::pi * 0.125, 0.02 * tight);  // 15 mm of tube and a round end
  EXPECT_NEAR(wide, tight, 1e-6 * tight);
  const auto r = run("mesh v.swc --out m --force --clip-box=0,0,0,1e10,1e10,1e10", dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--clip-box: 1e+10 is out of range; allowed: [-1e+06, 1e+06] mm"), std::string::npos) << r.err;
}

TEST(RobustnessGrid, ACellFarBelowItsBoxDoesNotWrapTheCellCount) {
  // 2e10 cells per axis asked: the integer product wrapped to a small number and the grid
  // allocated 8e30 cells (bad_alloc).
  SegmentGrid grid(Vec3(-10, -10, -10), Vec3(10, 10, 10), 1e-9, false);
  grid.insert(0, Vec3(0, 0, 0), Vec3(1, 0, 0), 0.1);
  bool found = false;
  grid.any(Vec3(0.5, 0, 0), Vec3(0.6, 0, 0), 0.1, [&](std::int32_t) { return found = true; });
  EXPECT_TRUE(found);
}

TEST_F(Robustness, GrammarRootDiameterBelowTheRangeIsRefused) {
  std::string t = slurp(test::sourceDir() / "examples/lsystem_grammar_3d.toml");
  t = std::regex_replace(t, std::regex("root_diameter = \"[0-9.]+ mm\""), "root_diameter = \"1e-6 mm\"");
  write("g.toml", t);
  const auto r = run("generate g.toml --out o --no-image", dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("root_diameter = 1e-06 is out of range; allowed: [0.0002, 2000] mm"), std::string::npos) << r.err;
}

// ---- Hangs -----------------------------------------------------------------------------------

std::string straightChain(int pieces, double length_mm) {
  std::string s = "1 1 0 -20 0 0.2 -1\n";
  for (int k = 0; k < pieces; ++k)
    s += std::to_string(k + 2) + " 3 0 " + std::to_string(-20 + (k + 1) * length_mm / pieces) + " 0 0.2 " + std::to_string(k + 1) + "\n";
  return s;
}

TEST_F(Robustness, DccoChainsGrowWhereAPieceCanBranchAndAreRefusedAtOnceWhereNone) {
  // 50 pieces of 0.2 mm, the radius their flow gives them: a branch's capsule overlaps the
  // pieces two beside it, which are pieces of its own vessel (every draw was refused for minutes).
  write("chain50.swc", straightChain(50, 10));
  write("c50.toml", dccoWithInitial("chain50.swc"));
  auto r = run("generate c50.toml --out o50 --no-image --quiet", dir_);
  EXPECT_EQ(r.code, 0) << r.err;
  // 1000 pieces of 0.01 mm: none can take a branch; refused before growth.
  write("chain1000.swc", straightChain(1000, 10));
  write("c1000.toml", dccoWithInitial("chain1000.swc"));
  r = run("generate c1000.toml --out o1000 --no-image --quiet", dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("no vessel of the initial network can take a branch"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("chain1000.swc:"), std::string::npos) << r.err;
}

// A shipped example with `edits` made (each once) and no volume formats, written as `name`.
void writeExample(const fs::path& dir, const std::string& example, const std::string& name,
                  const std::vector<std::pair<std::string, std::string>>& edits) {
  std::string t = slurp(test::sourceDir() / "examples" / example);
  for (const auto& [from, to] : edits) replaceOnce(t, from, to);
  replaceOnce(t, "formats = [\"nifti\", \"png\"]", "formats = []");
  std::ofstream(dir / name) << t;
}

TEST_F(Robustness, DccoRepairKeepsTheTerminalCountsOfAPolylineNetwork) {
  // VItA's tree with tortuous vessels as polylines (nodes of one child): the repair's removal of
  // subtrees added a continuation's missing second child, terminals[-1] (fuzz_initial_network).
  fs::copy_file(test::sourceDir() / "tests/data/network/tree_vita_polylines.vtp", dir_ / "p.vtp");
  write("p.toml",
        "seed = 1\n[domain]\nshape = \"disc\"\nradius = \"10 mm\"\nvoxel_size = \"0.2 mm\"\n[tree]\nmethod = \"dcco\"\n"
        "root_radius = \"0.2 mm\"\n[initial]\nfile = \"p.vtp\"\nbranching = \"versatile\"\nrole = \"distribution\"\n"
        "[physics]\nperfusion_flow = \"0.3 mL/min\"\n[[stage]]\nterminals = 12\n[image]\nformats = []\n");
  GrowthReport report;
  const auto g = test::growFile(dir_ / "p.toml", 1, &report);
  const auto& t = g.forest.vessels;
  ASSERT_GT(report.repair_rounds, 0) << "the repair did not run: the case no longer tests it";
  std::vector<std::int64_t> below(std::size_t(t.nodeCount()), 0);
  const auto order = t.topDownOrder();
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const auto i = *it;
    if (t.isRoot(i)) continue;
    below[std::size_t(i)] = t.child0[i] < 0 ? 1 : below[std::size_t(t.child0[i])] + (t.child1[i] >= 0 ? below[std::size_t(t.child1[i])] : 0);
    EXPECT_EQ(t.terminals[i], below[std::size_t(i)]) << "segment " << i;
  }
}

TEST_F(Robustness, DccoGaussiansOutsideTheirStageAreRefusedBeforeGrowth) {
  writeExample(dir_, "dcco_pdf_gaussian_2d.toml", "g.toml", {{"mean = [0, 0]", "mean = [500, 500]"}, {"sigma = [6, 6]", "sigma = [1, 1]"}});
  const auto r = run("generate g.toml --out o --no-image", dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("its Gaussians put 0 % of their mass inside its terminal region"), std::string::npos) << r.err;
}

TEST_F(Robustness, DccoRootOutsideItsFirstStagesDomainIsRefusedBeforeDrawing) {
  // The root sits on the 21 mm disc's border, 1 mm outside the ring its first stage distributes
  // in: a million draws (14 s) were refused one by one before the growth gave up.
  write("r.toml",
        "seed = 1\n[domain]\nshape = \"disc\"\nradius = \"21 mm\"\nvoxel_size = \"0.1 mm\"\n[tree]\nmethod = \"dcco\"\n"
        "root_radius = \"0.6 mm\"\n[physics]\nperfusion_flow = \"4 mL/min\"\n[[region]]\nname = \"ring\"\nshape = \"annulus\"\n"
        "inner_radius = \"12 mm\"\nouter_radius = \"20 mm\"\n[[stage]]\nname = \"ring\"\nterminals = 30\ndomain = [\"ring\"]\n"
        "[image]\nformats = []\n");
  const auto r = run("generate r.toml --out o --no-image", dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("lies 1 mm outside the stage's domain"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("allowed: a root at most 0.612 mm"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}

TEST_F(Robustness, DccoStageThatCannotConnectGivesUpAfterItsRelaxationsAndCountsWhatItPlaced) {
  // An initial network outside the disc, its two vessels from the inlet 3.4 degrees apart: every
  // connection crosses one of them. A million draws (19 s) were refused before growth gave up,
  // and the message counted a terminal the reader's restructuring made as placed.
  write("tree.swc", "1 1 0 32 0 0.2 -1\n2 2 5 24 0 0.2 1\n3 2 -11.413 11.314 0 0.15 2\n4 2 11.314 11.314 0 0.15 1\n");
  write("r.toml",
        "seed = 1\n[domain]\nshape = \"disc\"\nradius = \"10 mm\"\nvoxel_size = \"0.2 mm\"\n[tree]\nmethod = \"dcco\"\n"
        "root_radius = \"0.2 mm\"\n[initial]\nfile = \"tree.swc\"\nbranching = \"versatile\"\nrole = \"distribution\"\n"
        "[physics]\nperfusion_flow = \"0.3 mL/min\"\n[[stage]]\nterminals = 4\n[image]\nformats = []\n");
  const auto r = run("generate r.toml --out o --no-image", dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("placed 0 of its 4 terminals: 10000 points in a row"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}

TEST_F(Robustness, DccoRejectedTrialsLeaveNothingBehindSoACrowdedNetworkIsRefusedQuickly) {
  // A crowded network in which one terminal joins and no second can: every draw commits and
  // rolls back about seventy trials. Each rollback left its vessels in the segment index and the
  // list of thick vessels, so every draw searched more than the last: over two minutes where the
  // thousand draws of the budget take under a second.
  write("tree.swc",
        "1 1 0 20 0 0.3 -1\n2 2 0 13 0 0.3 1\n3 2 -8 12 0 0.2 2\n4 2 8 12 0 0.2 3\n5 2 -5 6 0 0.2 2\n"
        "6 2 1 11 0 0.2 2\n7 2 -1 9 0 0.2 6\n8 2 1 7 0 0.2 7\n9 2 0 5 0 0.2 8\n10 2 -4 -2 0 0.15 9\n"
        "11 2 7 -2 0 0.15 9\n12 2 0 -7 0 0.15 9\n");
  write("r.toml",
        "seed = 1\n[domain]\nshape = \"disc\"\nradius = \"10 mm\"\nvoxel_size = \"0.2 mm\"\n[tree]\nmethod = \"dcco\"\n"
        "root_radius = \"0.2 mm\"\n[initial]\nfile = \"tree.swc\"\nbranching = \"versatile\"\nrole = \"distribution\"\n"
        "[physics]\nperfusion_flow = \"0.3 mL/min\"\n[[stage]]\nterminals = 2\ndraws_before_relaxing = 10\n[image]\nformats = []\n");
  const auto r = run("generate r.toml --out o --no-image", dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("placed 1 of its 2 terminals: 1000 points in a row"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}

TEST_F(Robustness, CurvePiecesFarBelowTheVesselsStayFew) {
  writeExample(dir_, "cco_sphere_curved_3d.toml", "c.toml",
               {{"terminals = 4000", "terminals = 50"}, {"wall_clearance", "piece_length = \"1e-4 mm\"\nwall_clearance"}});
  const auto r = run("generate c.toml --out o --no-image --quiet", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(dir_ / "o" / "sample.json");
  const auto j = nlohmann::json::parse(in);
  // Without the floor of an eighth of the radius: about 1e7 pieces (did not finish in minutes).
  const auto nodes = j["statistics"]["curves"]["nodes_after"].get<std::int64_t>();
  EXPECT_LT(nodes, 400000);
  EXPECT_GT(nodes, 1000);
}

// ---- Memory limits ---------------------------------------------------------------------------

TEST_F(Robustness, VtpCountsBeyondTheLimitAreRefusedBeforeDecoding) {
  // 5e7 points declared, their 1.2 GB of coordinates as VTK's zlib blocks of 1 MiB of zeros
  // (about 1 KiB each packed): a file of 1.2 MB that decoded to 1.2 GB before anything checked
  // the limit (3.3 GB resident under --memory-limit 1).
  const std::uint64_t points = 50'000'000, bytes = points * 3 * 8, block = 1 << 20;
  const std::uint64_t blocks = (bytes + block - 1) / block, last = bytes - (blocks - 1) * block;
  const auto pack = [](std::uint64_t n) {
    const std::string zeros(n, '\0');
    std::string out(compressBound(uLong(n)), '\0');
    uLongf size = uLongf(out.size());
    compress(reinterpret_cast<Bytef*>(out.data()), &size, reinterpret_cast<const Bytef*>(zeros.data()), uLong(n));
    out.resize(size);
    return out;
  };
  const std::string full = pack(block), tail = pack(last);
  std::string header, body;
  const auto word = [&](std::uint64_t v) { header.append(reinterpret_cast<const char*>(&v), 8); };
  word(blocks), word(block), word(last);
  for (std::uint64_t b = 0; b < blocks; ++b) {
    word(b + 1 < blocks ? full.size() : tail.size());
    body += b + 1 < blocks ? full : tail;
  }
  const std::string text =
      "<?xml version=\"1.0\"?><VTKFile type=\"PolyData\" byte_order=\"LittleEndian\" header_type=\"UInt64\" "
      "compressor=\"vtkZLibDataCompressor\"><PolyData><Piece NumberOfPoints=\"" +
      std::to_string(points) +
      "\" NumberOfLines=\"1\"><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" "
      "offset=\"0\"/></Points></Piece></PolyData><AppendedData encoding=\"raw\">_" +
      header + body + "</AppendedData></VTKFile>";
  ASSERT_LT(text.size(), 2u << 20);
  const auto e = networkError("bomb.vtp", text, 1ULL << 30);
  EXPECT_NE(e.find("the Piece declares 50000000 points"), std::string::npos) << e;
  EXPECT_NE(e.find("more than the limit of 1"), std::string::npos) << e;
}

TEST_F(Robustness, TubesBeyondTheMemoryLimitAreRefusedBeforeMeshing) {
  // One vessel of a kilometre and 0.1 mm radius: 25 million triangles (a 1.25 GB STL was written
  // under a limit of 0.1 GiB).
  write("km.swc", "1 1 0 0 0 0.1 -1\n2 3 1e6 0 0 0.1 1\n");
  const auto r = run("mesh km.swc --out m --memory-limit 0.1", dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("the vessels' tubes make about 25"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "m"));
}

// ---- Nonsense with exit 0 --------------------------------------------------------------------

TEST_F(Robustness, AMeshVoxelCoarserThanTheThinnestVesselIsRefused) {
  write("y.swc", "1 1 0 0 0 0.5 -1\n2 3 10 0 0 0.5 1\n3 3 20 5 0 0.4 2\n4 3 20 -5 0 0.4 2\n");
  auto r = run("mesh y.swc --out m --voxel 1", dir_);  // an empty surface was written
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("allowed: at most 0.4 mm"), std::string::npos) << r.err;
  r = run("mesh y.swc --out m --voxel 0.4 --quiet", dir_);
  EXPECT_EQ(r.code, 0) << r.err;
}

TEST_F(Robustness, ATruncatedPredictionIsRefusedNotZeroFilled) {
  const fs::path sample = dir_ / "s";
  write("p.toml", selfContained(test::sourceDir() / "examples/vascusynth_like.toml"));
  std::string t = slurp(dir_ / "p.toml");
  replaceOnce(t, "terminals = 1000", "terminals = 40");
  write("p.toml", t);
  ASSERT_EQ(run("generate p.toml --out s --no-profiles --quiet --format nifti", dir_).code, 0);
  const auto whole = readNiftiVolume(sample / "mask.nii.gz", 1ULL << 30, 4, "the mask");
  // The mask uncompressed, then cut short; and its gzip stream cut short.
  const auto bytes = [&] {
    gzFile g = gzopen((sample / "mask.nii.gz").c_str(), "rb");
    std::string out;
    char buf[65536];
    for (int n; (n = gzread(g, buf, sizeof buf)) > 0;) out.append(buf, std::size_t(n));
    gzclose(g);
    return out;
  }();
  write("short.nii", bytes.substr(0, bytes.size() / 2));
  const std::string gz = slurp(sample / "mask.nii.gz");
  write("short.nii.gz", gz.substr(0, gz.size() / 3));
  for (const char* name : {"short.nii", "short.nii.gz"}) {
    try {
      readNiftiVolume(dir_ / name, 1ULL << 30, 4, "the prediction");
      ADD_FAILURE() << name << " was read";
    } catch (const InputError& e) { EXPECT_NE(std::string(e.what()).find("a truncated file"), std::string::npos) << e.what(); }
    const auto r = run(std::string("score ") + name + " s", dir_);
    EXPECT_EQ(r.code, 2) << name << ": " << r.err;
  }
  EXPECT_EQ(whole.values.data.size(), std::size_t(whole.values.grid.voxelCount()));
}

TEST_F(Robustness, ColonisationLengthsTheDomainCannotHoldAreRefused) {
  const std::string base = slurp(test::sourceDir() / "examples/colonisation_fig5_2d.toml");
  for (const auto& [key, why] :
       std::vector<std::pair<std::string, std::string>>{{"step = \"0 mm\"", "step 0 mm is out of range"},
                                                        {"step = \"1e6 mm\"", "step 1e+06 mm is out of range"},
                                                        {"terminal_radius = \"100 mm\"", "terminal_radius 100 mm is out of range"},
                                                        {"steps = 1\ndrains_per_step = 1\ndrain_spacing = \"9 mm\"", "the growth made no vessel"}}) {
    std::string t = std::regex_replace(base, std::regex("steps = 100\ndrains_per_step = 1000\n"), "");
    replaceOnce(t, "[[stage]]\n", "[[stage]]\n" + key + "\n");
    replaceOnce(t, "formats = [\"nifti\", \"png\"]", "formats = []");
    write("c.toml", t);
    const auto r = run("generate c.toml --out o --force --no-image", dir_);
    EXPECT_EQ(r.code, 2) << key << ": " << r.err;
    EXPECT_NE(r.err.find(why), std::string::npos) << key << ": " << r.err;
  }
}

TEST_F(Robustness, TreeNamesAreWhatGraphFilesTakeAsTheyAre) {
  std::string t = slurp(test::sourceDir() / "examples/cco_two_inlets_2d.toml");
  replaceOnce(t, "id = \"left\"", "id = \"a<b,\\\"c\"");
  write("n.toml", t);
  const auto r = run("generate n.toml --out o --no-image", dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("allowed: 1 to 60 letters, digits"), std::string::npos) << r.err;
}

TEST_F(Robustness, An2dDomainTakesAnInitialNetworkInOnePlaneOnly) {
  write("z.swc", "1 1 0 -20 0 0.2 -1\n2 3 0 -14 0 0.2 1\n3 3 -7 -7 3 0.15 2\n4 3 7 -7 0 0.15 2\n");
  write("z.toml", dccoWithInitial("z.swc"));
  const auto r = run("generate z.toml --out o --no-image", dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("z.swc:3: node 3 has z = 3 mm"), std::string::npos) << r.err;
}

TEST_F(Robustness, AnInitialVesselSetTwiceIsRefused) {
  write("t.swc", "1 1 0 -20 0 0.2 -1\n2 3 0 -14 0 0.2 1\n3 3 -7 -7 0 0.15 2\n4 3 7 -7 0 0.15 2\n");
  write("t.toml", dccoWithInitial("t.swc", "[[initial.vessel]]\nid = 3\nbranching = \"none\"\n[[initial.vessel]]\nid = 3\nbranching = \"fixed\"\n"));
  const auto r = run("generate t.toml --out o --no-image", dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("vessel id 3 is set again (first on line"), std::string::npos) << r.err;
}

TEST_F(Robustness, GraphFilesCarryTheirWallsToTheHollowWallMesh) {
  // The CSV pair, GXL and VTP as angiosynth writes a tapered tree with walls: read back, every
  // vessel has its wall (the CSV reader dropped the columns, and --wall-from-graph refused).
  write("w_nodes.csv", "id,pos_x,pos_y,pos_z\n0,0,0,0\n1,6,0,0\n");
  write("w_edges.csv", "id,node1id,node2id,radius,radius_start,wall_start,wall\n1,0,1,0.4,0.5,0.1,0.08\n");
  const auto net = readNetwork(dir_ / "w_edges.csv");
  ASSERT_EQ(net.tree.nodeCount(), 2);
  EXPECT_DOUBLE_EQ(net.tree.wall_start[1], 0.1);
  EXPECT_DOUBLE_EQ(net.tree.wall[1], 0.08);
  EXPECT_DOUBLE_EQ(net.tree.radius_start[1], 0.5);
  const auto r = run("mesh w_edges.csv --out m --wall-from-graph --quiet", dir_);
  EXPECT_EQ(r.code, 0) << r.err;
  // What mesh reads back from its own graph writers: the same walls.
  for (
      const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
          {"w.gxl",
           R"(<?xml version="1.0"?><gxl><graph id="t"><node id="a"><attr name="position"><tup><float>0</float><float>0</float><float>0</float></tup></attr></node><node id="b"><attr name="position"><tup><float>6</float><float>0</float><float>0</float></tup></attr></node><edge from="a" to="b"><attr name="radius"><float>0.4</float></attr><attr name="radius_start"><float>0.5</float></attr><attr name="wall_start"><float>0.1</float></attr><attr name="wall"><float>0.08</float></attr></edge></graph></gxl>)"},
          {"w.vtp",
           "<?xml version=\"1.0\"?><VTKFile type=\"PolyData\" byte_order=\"LittleEndian\"><PolyData><Piece NumberOfPoints=\"2\" "
           "NumberOfLines=\"1\"><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0 6 0 0</DataArray>"
           "</Points><CellData><DataArray type=\"Float64\" Name=\"Radius\" format=\"ascii\">0.4</DataArray><DataArray type=\"Float64\" "
           "Name=\"RadiusStart\" format=\"ascii\">0.5</DataArray><DataArray type=\"Float64\" Name=\"WallStart\" format=\"ascii\">0.1"
           "</DataArray><DataArray type=\"Float64\" Name=\"Wall\" format=\"ascii\">0.08</DataArray></CellData><Lines><DataArray "
           "type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1</DataArray><DataArray type=\"Int64\" Name=\"offsets\" "
           "format=\"ascii\">2</DataArray></Lines></Piece></PolyData></VTKFile>"}}) {
    const auto n = readNetwork(write(name, text));
    ASSERT_EQ(n.tree.nodeCount(), 2) << name;
    EXPECT_DOUBLE_EQ(n.tree.wall_start[1], 0.1) << name;
    EXPECT_DOUBLE_EQ(n.tree.wall[1], 0.08) << name;
    EXPECT_DOUBLE_EQ(n.tree.radius_start[1], 0.5) << name;
  }
}

}  // namespace
