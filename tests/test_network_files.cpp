// Initial networks read from every graph file the project writes (GXL, the CSV pair, VTP, .cco,
// SWC) give back the grown tree, and VTP files that VTK itself wrote (scripts/
// vtk_network_fixtures.py: every encoding, and VItA's layout with polylines) read alike.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.hpp"
#include "domain/growth_domain.hpp"
#include "io/graph_writers.hpp"
#include "io/network_files.hpp"
#include "grow_file.hpp"
#include "test_support.hpp"

using namespace angiosynth;

namespace {

std::filesystem::path scratch() {
  const auto dir = std::filesystem::temp_directory_path() / ("angiosynth_network_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

// `read` holds `want`'s segments (matched by distal point, so the order may differ), with the
// same parent, radius, stage, role and branching; ids of read segments are checked elsewhere.
void expectSameNetwork(const VascularTree& read, const VascularTree& want, const std::string& what, bool attributes = true) {
  ASSERT_EQ(read.nodeCount(), want.nodeCount()) << what;
  ASSERT_EQ(read.roots().size(), want.roots().size()) << what;
  std::map<std::array<double, 3>, std::int32_t> at;
  for (std::int32_t i = 0; i < want.nodeCount(); ++i) at[{want.position[i].x, want.position[i].y, want.position[i].z}] = i;
  std::int64_t differ = 0;
  for (std::int32_t i = 0; i < read.nodeCount(); ++i) {
    const auto it = at.find({read.position[i].x, read.position[i].y, read.position[i].z});
    ASSERT_NE(it, at.end()) << what << ": node " << i << " is not a node of the tree";
    const auto j = it->second;
    ASSERT_EQ(read.isRoot(i), want.isRoot(j)) << what;
    if (read.isRoot(i)) continue;
    differ += distance(read.position[read.parent[i]], want.position[want.parent[j]]) > 0;
    differ += std::abs(read.radius[i] - want.radius[j]) > 1e-12 * want.radius[j];
    if (attributes) differ += read.stage[i] != want.stage[j] || read.role[i] != want.role[j] || read.branching[i] != want.branching[j];
  }
  EXPECT_EQ(differ, 0) << what;
}

// Writes dir/name with writer(stream); returns its path.
template <class Writer>
std::filesystem::path writeFile(const std::filesystem::path& dir, const std::string& name, Writer&& writer) {
  std::ofstream out(dir / name);
  writer(out);
  return dir / name;
}

}  // namespace

TEST(NetworkFiles, EveryGraphFormatTheProjectWritesReadsBackTheGrownTree) {
  const auto g = test::growFile(test::sourceDir() / "examples/dcco_outlet_half_2d.toml");
  const auto& t = g.forest.vessels;
  ASSERT_GT(t.nodeCount(), 900);
  const auto dir = scratch();
  GraphFrame frame;
  frame.voxel_mm = 0.1;
  const auto write = [&](const std::string& name, auto&& writer) { return writeFile(dir, name, writer); };
  const auto gxl = write("tree.gxl", [&](std::ostream& o) { writeGxl(o, t, g.forest.trees, frame, "tree"); });
  write("nodes.csv", [&](std::ostream& o) { writeNodesCsv(o, t, g.forest.trees); });
  const auto edges = write("edges.csv", [&](std::ostream& o) { writeEdgesCsv(o, t, g.forest.trees); });
  const auto vtp = write("centerlines.vtp", [&](std::ostream& o) { writeVtp(o, t, g.forest.trees); });
  const auto swc = write("tree.swc", [&](std::ostream& o) { writeSwc(o, t, g.forest.trees); });
  expectSameNetwork(readNetwork(gxl).tree, t, "gxl");
  expectSameNetwork(readNetwork(edges).tree, t, "csv (edges named)");
  expectSameNetwork(readNetwork(dir / "nodes.csv").tree, t, "csv (nodes named)");
  expectSameNetwork(readNetwork(vtp).tree, t, "vtp");
  // SWC carries no stages or roles; its root node's radius is the root vessel's.
  expectSameNetwork(readNetwork(swc).tree, t, "swc", false);
  // Ids are the files' segment ids: in the GXL the edge e<i> is segment i.
  const auto net = readNetwork(gxl);
  for (std::int32_t i = 0; i < net.tree.nodeCount(); ++i)
    if (!net.tree.isRoot(i)) {
      const auto seg = std::stoi(net.ids[std::size_t(i)].substr(1));
      EXPECT_LE(distance(net.tree.position[i], t.position[seg]), 0.0);
    }
  // Millimetres scale with the unit: a file in cm reads ten times larger.
  const auto cm = readNetwork(vtp, 10.0).tree;
  EXPECT_DOUBLE_EQ(cm.radius[1], 10 * readNetwork(vtp).tree.radius[1]);
}

// An N-ary junction (a node with three or more children) reads as a chain of links at its point
// and every graph writer merges the chain back: one node with all its children, no zero-length
// edge; each format reads back as the same network (the .cco to 1e-12, as VItA's users need).
TEST(NetworkFiles, NaryJunctionsAreKeptThroughEveryGraphFormat) {
  const auto swc_in = test::sourceDir() / "examples/dcco_junctions_t0_2d.swc";
  const auto net = readNetwork(swc_in);
  const auto& n = net.tree;
  // 12 samples: the root point, 11 vessels; links: 2 for the four children of sample 2, 1 for
  // the three of sample 9.
  std::int32_t links = 0;
  for (std::int32_t i = 0; i < n.nodeCount(); ++i) links += n.isLink(i);
  EXPECT_EQ(n.nodeCount(), 12 + 3);
  EXPECT_EQ(links, 3);
  std::map<int, int> degree;  // children → junctions
  for (std::int32_t i = 0; i < n.nodeCount(); ++i)
    if (!n.isLink(i) && n.graphType(i) == NodeType::Junction) {
      std::vector<std::int32_t> kids;
      n.junctionChildren(i, kids);
      ++degree[int(kids.size())];
    }
  EXPECT_EQ(degree, (std::map<int, int>{{3, 1}, {4, 1}}));

  // The grown tree (every vessel of the network takes branches) through every writer.
  const auto g = test::growFile(test::sourceDir() / "examples/dcco_junctions_2d.toml");
  const auto& t = g.forest.vessels;
  const auto dir = scratch() / "nary";
  std::filesystem::create_directories(dir);
  GraphFrame frame;
  frame.voxel_mm = 0.1;
  const auto write = [&](const std::string& name, auto&& writer) { return writeFile(dir, name, writer); };
  const std::vector<std::filesystem::path> files = {write("tree.gxl", [&](std::ostream& o) { writeGxl(o, t, g.forest.trees, frame, "tree"); }),
                                                    write("edges.csv", [&](std::ostream& o) { writeEdgesCsv(o, t, g.forest.trees); }),
                                                    write("centerlines.vtp", [&](std::ostream& o) { writeVtp(o, t, g.forest.trees); }),
                                                    write("tree.swc", [&](std::ostream& o) { writeSwc(o, t, g.forest.trees); }),
                                                    write("tree.cco", [&](std::ostream& o) { writeCco(o, t, g.forest.trees); })};
  write("nodes.csv", [&](std::ostream& o) { writeNodesCsv(o, t, g.forest.trees); });
  // The tree's segments (links merged) by distal point: proximal point and radius.
  const auto segments = [](const VascularTree& v) {
    std::map<std::array<double, 3>, std::pair<Vec3, double>> out;
    for (std::int32_t i = 0; i < v.nodeCount(); ++i)
      if (!v.isRoot(i) && !v.isLink(i)) out[{v.position[i].x, v.position[i].y, v.position[i].z}] = {v.position[v.junction(v.parent[i])], v.radius[i]};
    return out;
  };
  const auto want = segments(t);
  ASSERT_GT(want.size(), 1000u);
  for (const auto& f : files) {
    const auto back = readNetwork(f).tree;
    std::int32_t back_links = 0, zero = 0;
    for (std::int32_t i = 0; i < back.nodeCount(); ++i) back_links += back.isLink(i);
    EXPECT_EQ(back_links, 3) << f.filename();
    const auto got = segments(back);
    ASSERT_EQ(got.size(), want.size()) << f.filename();
    double worst = 0;
    for (const auto& [end, seg] : want) {
      const auto it = got.find(end);
      ASSERT_NE(it, got.end()) << f.filename();
      zero += !(distance(it->second.first, Vec3(end[0], end[1], end[2])) > 0);
      EXPECT_EQ(distance(it->second.first, seg.first), 0.0) << f.filename();
      worst = std::max(worst, std::abs(it->second.second - seg.second) / seg.second);
    }
    EXPECT_EQ(zero, 0) << f.filename();
    EXPECT_LE(worst, 1e-12) << f.filename();
  }
  // In the files themselves: the junctions are nodes with 4 and 3 outgoing edges, and no edge
  // has zero length.
  std::ifstream edges(dir / "edges.csv");
  std::string line;
  std::getline(edges, line);
  std::map<std::string, int> out_edges;
  std::int64_t zero_length = 0;
  while (std::getline(edges, line)) {
    std::vector<std::string> c;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) c.push_back(x);
    ++out_edges[c[1]];
    zero_length += !(std::stod(c[3]) > 0);
  }
  std::map<int, int> csv_degree;
  for (const auto& [node, k] : out_edges)
    if (k >= 3) ++csv_degree[k];
  EXPECT_EQ(csv_degree, (std::map<int, int>{{3, 1}, {4, 1}}));
  EXPECT_EQ(zero_length, 0);
  // The .cco round trip: read → write → read gives the same vessels.
  const auto cco1 = readNetwork(dir / "tree.cco");
  write("again.cco", [&](std::ostream& o) { writeCco(o, cco1.tree, g.forest.trees); });
  const auto cco2 = segments(readNetwork(dir / "again.cco").tree);
  EXPECT_EQ(cco2, segments(cco1.tree));
}

// The same tree written by VTK in each of its encodings (inline base64 with zlib blocks and
// without, appended raw with UInt64 headers, appended base64) reads as our ascii file does.
TEST(NetworkFiles, VtpFilesWrittenByVtkReadInEveryEncoding) {
  const auto dir = test::sourceDir() / "tests/data/network";
  const auto ascii = readNetwork(dir / "tree_ascii.vtp");
  EXPECT_EQ(ascii.tree.nodeCount(), 64);
  for (const char* name : {"tree_binary_zlib.vtp", "tree_binary_plain.vtp", "tree_appended_raw_zlib64.vtp", "tree_appended_base64.vtp"})
    expectSameNetwork(readNetwork(dir / name).tree, ascii.tree, name);
}

// VItA's layout: each vessel has its own points (coincident points are one node), VItA's codes
// for function and branching, and here three-point polylines: a chain of two unary segments
// per vessel, kept as it is, so the tree has one node more per vessel and the same geometry.
TEST(NetworkFiles, VitaLayoutWithPolylinesKeepsChainsOfUnarySegments) {
  const auto dir = test::sourceDir() / "tests/data/network";
  const auto ascii = readNetwork(dir / "tree_ascii.vtp").tree;
  const auto vita = readNetwork(dir / "tree_vita_polylines.vtp");
  const auto& v = vita.tree;
  const std::int64_t segments = ascii.nodeCount() - std::int64_t(ascii.roots().size());
  ASSERT_EQ(v.nodeCount(), ascii.nodeCount() + segments);
  std::map<std::array<double, 3>, std::int32_t> at;
  for (std::int32_t i = 0; i < ascii.nodeCount(); ++i) at[{ascii.position[i].x, ascii.position[i].y, ascii.position[i].z}] = i;
  std::int64_t chains = 0, differ = 0;
  for (std::int32_t i = 0; i < v.nodeCount(); ++i) {
    const auto it = at.find({v.position[i].x, v.position[i].y, v.position[i].z});
    if (it == at.end()) {  // a midpoint: one child, halfway between its parent and child
      ASSERT_TRUE(v.child0[i] >= 0 && v.child1[i] < 0);
      const auto c = v.child0[i];
      differ += distance(v.position[i], (v.position[v.parent[i]] + v.position[c]) * 0.5) > 1e-12;
      differ += vita.ids[std::size_t(i)] != vita.ids[std::size_t(c)].substr(0, vita.ids[std::size_t(c)].size() - 2) + ".0";
      ++chains;
      continue;
    }
    const auto j = it->second;
    if (v.isRoot(i)) continue;
    const auto mid = v.parent[i];
    differ += distance(v.position[v.parent[mid]], ascii.position[ascii.parent[j]]) > 0;
    differ += std::abs(v.radius[i] - ascii.radius[j]) > 1e-12 * ascii.radius[j] || v.radius[mid] != v.radius[i];
    differ += v.stage[i] != ascii.stage[j] || v.role[i] != ascii.role[j] || v.branching[i] != ascii.branching[j];
  }
  EXPECT_EQ(chains, segments);
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(vita.ids[1].substr(0, 3), "100") << "ids come from VItA's ID_Vessel";
}

// Malformed networks are refused with the file's line and what is allowed.
TEST(NetworkFiles, BadNetworkFilesNameTheLineAndWhatIsAllowed) {
  const auto dir = scratch();
  const auto expectError = [&](const std::string& name, const std::string& text, const std::string& fragment) {
    std::ofstream(dir / name) << text;
    try {
      readNetwork(dir / name);
      ADD_FAILURE() << name << " was accepted";
    } catch (const InputError& e) { EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what(); }
  };
  // SWC and VItA's .cco.
  expectError("orphan.swc", "1 1 0 0 0 1 -1\n2 2 1 0 0 1 7\n", "orphan.swc:2: parent 7 of 2 is not defined");
  expectError("cycle.swc", "1 1 0 0 0 1 -1\n2 2 1 0 0 1 3\n3 2 2 0 0 1 2\n", "is not connected to a root");
  expectError("bad.swc", "1 1 0 0 zero 1 -1\n", "bad.swc:1: z 'zero' is not a finite number");
  expectError("x.vtk", "", "unknown network format '.vtk'; allowed: .cco (VItA), .swc");
  expectError("gap.cco",
              "*Vessels\n2\n0 0 0 0 1 0 0 0 0 0 0 2 1 0 0 0 0 0 0 0 -1\n1 1 0.5 0 2 0 0 0 0 0 0 2 1 0 0 0 0 0 0 0 -1\n*Connectivity\n0 -1 1\n1 0\n",
              "gap.cco:4: vessel 1 starts at 1 0.5 0, not where its parent 0 ends (1 0 0)");
  expectError("mode.cco", "*Vessels\n1\n0 0 0 0 1 0 0 0 0 0 0 4 1 0 0 0 0 0 0 0 -1\n*Connectivity\n0 -1\n",
              "mode.cco:3: branching mode 4; allowed: 0 (none)");
  // GXL, CSV and VTP.
  const std::string node0 = "<node id=\"a\"><attr name=\"position\"><tup><float>0</float><float>0</float><float>0</float></tup></attr></node>\n";
  const std::string node1 = "<node id=\"b\"><attr name=\"position\"><tup><float>1</float><float>0</float><float>0</float></tup></attr></node>\n";
  const std::string node2 = "<node id=\"c\"><attr name=\"position\"><tup><float>2</float><float>0</float><float>0</float></tup></attr></node>\n";
  const auto edge = [](const char* id, const char* from, const char* to) {
    return std::string("<edge id=\"") + id + "\" from=\"" + from + "\" to=\"" + to + "\"><attr name=\"radius\"><float>0.1</float></attr></edge>\n";
  };
  expectError("cycle.gxl",
              "<gxl><graph>\n" + node0 + node1 + node2 + edge("e1", "a", "b") + edge("e2", "b", "c") + edge("e3", "c", "b") + "</graph></gxl>\n",
              "cycle.gxl:7: vessels e1 and e3 both end at 1 0 0: a node of a tree has one parent vessel");
  expectError("noradius.gxl", "<gxl><graph>\n" + node0 + node1 + "<edge id=\"e\" from=\"a\" to=\"b\"/>\n</graph></gxl>\n",
              "noradius.gxl:4: edge e has no 'radius' attribute (mm)");
  expectError("unknown.gxl", "<gxl><graph>\n" + node0 + edge("e", "a", "z") + "</graph></gxl>\n",
              "unknown.gxl:3: edge e refers to node z, which is not defined");
  expectError("vs.gxl", "<gxl><graph>\n<node id=\"n0\"><attr name=\" position\"><tup><float>0</float></tup></attr></node>\n</graph></gxl>\n",
              "vs.gxl:2: node n0 has no attribute 'position'");
  expectError("broken.gxl", "<gxl><graph>\n<node id=\"a\">\n</graph></gxl>\n", "broken.gxl:");
  std::ofstream(dir / "bad_nodes.csv") << "id,pos_x,pos_y,pos_z\n0,0,0,0\n1,1,0,0\n";
  expectError("bad_edges.csv", "id,node1id,node2id,radius,role\n1,0,1,0.1,artery\n",
              "bad_edges.csv:2: role 'artery'; allowed: distribution, transport, perforator");
  expectError("lonely_edges.csv", "id,node1id,node2id,radius\n1,0,1,0.1\n", "lonely_nodes.csv: cannot read the network file");
  expectError("table.csv", "a,b\n", "a CSV network is a pair of files whose names contain 'nodes' and 'edges'");
  const std::string head =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" byte_order=\"LittleEndian\">\n<PolyData>\n"
      "<Piece NumberOfPoints=\"2\" NumberOfLines=\"1\">\n<Points>\n"
      "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0 1 0 0</DataArray>\n</Points>\n";
  expectError("lz4.vtp", "<VTKFile type=\"PolyData\" compressor=\"vtkLZ4DataCompressor\"></VTKFile>\n",
              "lz4.vtp:1: compressor vtkLZ4DataCompressor; allowed: vtkZLibDataCompressor");
  expectError("noradius.vtp",
              head +
                  "<Lines>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1</DataArray>\n"
                  "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">2</DataArray>\n</Lines>\n</Piece>\n</PolyData>\n</VTKFile>\n",
              "noradius.vtp:4: no radius: a cell or point array named Radius or radius is required");
  expectError("short.vtp",
              head +
                  "<CellData><DataArray type=\"Float64\" Name=\"radius\" format=\"binary\">AAAAAA==</DataArray></CellData>\n<Lines>\n"
                  "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1</DataArray>\n"
                  "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">2</DataArray>\n</Lines>\n</Piece>\n</PolyData>\n</VTKFile>\n",
              "short.vtp:8: the DataArray's binary data declares 0 bytes; the Piece asks for 8");
  expectError("point.vtp",
              head +
                  "<CellData><DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">0.1</DataArray></CellData>\n<Lines>\n"
                  "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 5</DataArray>\n"
                  "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">2</DataArray>\n</Lines>\n</Piece>\n</PolyData>\n</VTKFile>\n",
              "point.vtp:10: line 0 refers to a point that is not defined");
}

// Growth continues from a tree angiosynth wrote ([initial] origin = "corner": positions as its
// graphs give them): the given vessels keep their places, and the new terminals join them.
TEST(NetworkFiles, GrowthContinuesFromTheProjectsOwnVtp) {
  const auto dir = scratch();
  std::ofstream(dir / "continue.toml") << "seed = 2\n[domain]\nshape = \"disc\"\nradius = \"20 mm\"\nvoxel_size = \"0.1 mm\"\n"
                                          "[tree]\nmethod = \"dcco\"\n[initial]\nfile = \""
                                       << (test::sourceDir() / "tests/data/network/tree_ascii.vtp").string()
                                       << "\"\norigin = \"corner\"\n[physics]\nperfusion_flow = \"0.14 mL/min\"\n"
                                          "[[stage]]\nname = \"more\"\nterminals = 100\n";
  const auto g = test::growFile(dir / "continue.toml");
  const auto given = readNetwork(test::sourceDir() / "tests/data/network/tree_ascii.vtp").tree;
  const auto& t = g.forest.vessels;
  const auto disc = GrowthDomain::analytic(DomainShape::Disc, 20, 0.1);
  // Given nodes keep their places (to 1e-12 mm: the plane's z is recomputed); new terminals lie in the disc.
  const auto nearest = [](const VascularTree& v, const Vec3& p) {
    double best = 1e300;
    for (std::int32_t j = 0; j < v.nodeCount(); ++j) best = std::min(best, distance(v.position[j], p));
    return best;
  };
  std::int64_t moved = 0, terminals = 0, new_outside = 0;
  for (std::int32_t i = 0; i < given.nodeCount(); ++i) moved += nearest(t, given.position[i]) > 1e-12;
  for (std::int32_t i = 0; i < t.nodeCount(); ++i)
    if (!t.isRoot(i) && t.child0[i] < 0) {
      ++terminals;
      new_outside += nearest(given, t.position[i]) > 1e-12 && !(disc.depth(t.position[i]) > 0);
    }
  EXPECT_EQ(moved, 0);
  EXPECT_EQ(terminals, 32 + 100);
  EXPECT_EQ(new_outside, 0) << "origin = corner puts the given tree over the disc, where the new terminals are";
}

// A junction of 20,000 children (a chain of 19,998 links) reads, counts its children and writes
// back as one node, without deep recursion.
TEST(NetworkFiles, AJunctionOfThousandsOfChildrenIsOneNode) {
  const auto dir = scratch();
  {
    std::ofstream swc(dir / "star.swc");
    swc << "1 1 0 0 0 1 -1\n2 2 0 0 10 1 1\n";
    for (int k = 0; k < 20000; ++k) swc << k + 3 << " 2 " << std::cos(k * 0.001) * 5 << ' ' << std::sin(k * 0.001) * 5 << " 10 0.01 2\n";
  }
  const auto t = readNetwork(dir / "star.swc").tree;
  std::int32_t links = 0, junction = -1;
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    links += t.isLink(i);
    if (!t.isLink(i) && t.graphType(i) == NodeType::Junction) junction = i;
  }
  EXPECT_EQ(links, 19998);
  ASSERT_GE(junction, 0);
  std::vector<std::int32_t> kids;
  t.junctionChildren(junction, kids);
  EXPECT_EQ(kids.size(), 20000u);
  std::ostringstream edges;
  writeEdgesCsv(edges, t, {TreeInfo{}});
  const std::string text = edges.str();
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1 + 1 + 20000);  // header, root vessel, children
}
