// The Python module's native part (angiosynth._core): the pipeline's front doors, bound as they
// are. A sample comes back as the volumes the pipeline kept in memory (NumPy arrays over the
// module's own buffers), the graph as columns, and the sidecar as JSON text for the Python side.
// Work runs on a thread of its own with the GIL released; the caller's thread waits and checks
// for Ctrl-C, which cancels the work at its next progress point.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <tbb/global_control.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include "segment/segment.hpp"
#include "angiosynth/version.hpp"
#include "config/scenario.hpp"
#include "core/error.hpp"
#include "core/memory.hpp"
#include "core/vessel_roles.hpp"
#include "dataset/run_dataset.hpp"
#include "dataset/spec.hpp"
#include "degrade/profile.hpp"
#include "files/staged_directory.hpp"
#include "io/graph_writers.hpp"
#include "io/nifti_reader.hpp"
#include "io/volume_writers.hpp"
#include "pipeline/generate_sample.hpp"
#include "pipeline/mesh_outputs.hpp"
#include "score/case_scores.hpp"
#include "score/label_schemes.hpp"

namespace py = pybind11;
using namespace angiosynth;

namespace {

using Cancel = std::function<bool()>;

// Runs work(cancelled) on its own thread with at most `threads` TBB workers (0: every core),
// the GIL released. A KeyboardInterrupt (or any signal handler's exception) seen while waiting
// cancels the work, waits for its thread to stop, and is raised; the work's own exception is
// rethrown as it is.
template <class Result>
Result runReleased(const std::function<Result(const Cancel&)>& work, int threads) {
  std::atomic<bool> cancel{false};
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  std::optional<Result> result;
  std::exception_ptr error;
  std::optional<py::error_already_set> interrupt;
  std::thread worker([&] {
    try {
      std::optional<tbb::global_control> limit;
      if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
      result.emplace(work([&] { return cancel.load(std::memory_order_relaxed); }));
    } catch (...) { error = std::current_exception(); }
    std::lock_guard<std::mutex> lock(m);
    done = true;
    cv.notify_all();
  });
  {
    py::gil_scoped_release release;
    std::unique_lock<std::mutex> lock(m);
    while (!done) {
      cv.wait_for(lock, std::chrono::milliseconds(50));
      if (done || cancel) continue;
      lock.unlock();
      {
        py::gil_scoped_acquire acquire;
        if (PyErr_CheckSignals() != 0) {
          interrupt.emplace();  // takes the pending exception
          cancel = true;
        }
      }
      lock.lock();
    }
  }
  worker.join();
  if (interrupt) throw std::move(*interrupt);
  if (error) std::rethrow_exception(error);
  return std::move(*result);
}

// The parameters of generate(): a parameter file, or TOML text read as if it were a file named
// `name` in the working directory.
Scenario readScenario(const std::string& file, const std::string& text, const std::string& name) {
  if (text.empty()) return readParameters(file);
  toml::table root;
  try {
    root = toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    throw InputError(name, static_cast<int>(e.source().begin.line), std::string("not valid TOML: ") + std::string(e.description()));
  }
  return readTomlParameters(root, name);  // relative paths: from the working directory
}

py::dtype dtypeOf(VoxelType t) {
  switch (t) {
    case VoxelType::UInt8: return py::dtype::of<std::uint8_t>();
    case VoxelType::Int16: return py::dtype::of<std::int16_t>();
    case VoxelType::UInt16: return py::dtype::of<std::uint16_t>();
    case VoxelType::UInt32: return py::dtype::of<std::uint32_t>();
    case VoxelType::Float32: return py::dtype::of<float>();
  }
  return py::dtype::of<float>();
}

// A volume as an (x, y, z) array over its own buffer, which the array keeps alive: the layout
// of the files (x fastest), indexed as nibabel indexes them.
py::array volumeArray(CapturedVolume&& v) {
  auto* owner = new std::vector<std::uint8_t>(std::move(v.bytes));
  py::capsule base(owner, [](void* p) { delete static_cast<std::vector<std::uint8_t>*>(p); });
  const auto item = static_cast<py::ssize_t>(voxelBytes(v.type));
  const auto nx = static_cast<py::ssize_t>(v.grid.dims[0]), ny = static_cast<py::ssize_t>(v.grid.dims[1]);
  const std::vector<py::ssize_t> shape{nx, ny, static_cast<py::ssize_t>(v.grid.dims[2])}, strides{item, item * nx, item * nx * ny};
  return py::array(dtypeOf(v.type), shape, strides, owner->data(), base);
}

template <class T>
py::array column(const std::vector<T>& values) {
  return py::array_t<T>(static_cast<py::ssize_t>(values.size()), values.data());
}

// The graph as the CSV export writes it (nodes.csv, edges.csv): one row per node and per
// segment, junction links merged, as NumPy columns.
py::dict graphColumns(const VascularTree& t, const std::vector<TreeInfo>& trees) {
  std::vector<std::int32_t> id, tree_index;
  std::vector<double> x, y, z, pressure, node_radius;
  std::vector<std::string> type, tree_id, kind;
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    if (t.isLink(i)) continue;
    id.push_back(i);
    x.push_back(t.position[i].x), y.push_back(t.position[i].y), z.push_back(t.position[i].z);
    type.push_back(nodeTypeName(t.graphType(i)));
    pressure.push_back(t.pressure[i]);
    node_radius.push_back(nodeRadius(t, i));
    tree_index.push_back(t.tree[i]);
    tree_id.push_back(treeOf(trees, t, i).id);
    kind.push_back(treeOf(trees, t, i).kind);
  }
  py::dict nodes;
  nodes["id"] = column(id), nodes["pos_x"] = column(x), nodes["pos_y"] = column(y), nodes["pos_z"] = column(z);
  nodes["type"] = type, nodes["pressure"] = column(pressure), nodes["radius"] = column(node_radius);
  nodes["tree_index"] = column(tree_index), nodes["tree"] = tree_id, nodes["kind"] = kind;

  std::vector<std::int32_t> eid, from, to, stage, e_tree_index, class_label;
  std::vector<double> length, radius, flow, volume, radius_start, wall_start, wall;
  std::vector<std::string> e_tree, e_kind, role, branching;
  const bool staged = t.hasStages(), tapered = t.hasTapers() || t.hasWalls();
  for (std::int32_t i = 1; i < t.nodeCount(); ++i) {
    if (t.isRoot(i) || t.isLink(i)) continue;
    const TreeInfo& tr = treeOf(trees, t, i);
    eid.push_back(i), from.push_back(t.junction(t.parent[i])), to.push_back(i);
    length.push_back(t.length[i]), radius.push_back(t.radius[i]), flow.push_back(t.flow[i]), volume.push_back(segmentVolume(t, i));
    e_tree_index.push_back(t.tree[i]), e_tree.push_back(tr.id), e_kind.push_back(tr.kind), class_label.push_back(tr.class_label);
    if (staged) stage.push_back(t.stage[i]), role.push_back(roleName(t.role[i])), branching.push_back(branchingName(t.branching[i]));
    if (tapered) radius_start.push_back(t.startRadius(i)), wall_start.push_back(t.wall_start[i]), wall.push_back(t.wall[i]);
  }
  py::dict edges;
  edges["id"] = column(eid), edges["node1id"] = column(from), edges["node2id"] = column(to);
  edges["length"] = column(length), edges["radius"] = column(radius), edges["flow"] = column(flow), edges["volume"] = column(volume);
  edges["tree_index"] = column(e_tree_index), edges["tree"] = e_tree, edges["kind"] = e_kind, edges["class"] = column(class_label);
  if (staged) edges["stage"] = column(stage), edges["role"] = role, edges["branching"] = branching;
  if (tapered) edges["radius_start"] = column(radius_start), edges["wall_start"] = column(wall_start), edges["wall"] = column(wall);
  py::dict graph;
  graph["nodes"] = nodes;
  graph["edges"] = edges;
  return graph;
}

// A sample's native half, held by the Python Sample: its forest and grid, for the graph and for
// the truth files score() writes.
struct NativeSample {
  Forest forest;
  VolumeGrid grid;
  bool has_grid = false;
  std::vector<WarpedTree> warped;
  std::string sidecar;  // sample.json's JSON
};

py::dict sampleDict(SampleCapture&& capture, const SampleSummary& summary) {
  py::dict volumes;
  for (auto& v : capture.volumes) {
    const std::string role = v.role;
    volumes[role.c_str()] = volumeArray(std::move(v));
  }
  py::dict out;
  out["volumes"] = volumes;
  out["graph"] = graphColumns(capture.forest.vessels, capture.forest.trees);
  py::dict warped;
  for (const auto& w : capture.warped) warped[w.profile.c_str()] = graphColumns(w.tree, capture.forest.trees);
  out["warped_graphs"] = warped;
  auto native = std::make_shared<NativeSample>();
  native->forest = std::move(capture.forest);
  native->grid = capture.grid;
  native->has_grid = capture.has_grid;
  native->warped = std::move(capture.warped);
  native->sidecar = summary.sidecar.dump();
  if (capture.has_grid) {
    const VolumeGrid& g = capture.grid;
    out["dims"] = py::make_tuple(g.dims[0], g.dims[1], g.dims[2]);
    out["spacing"] = py::make_tuple(g.spacing_mm.x, g.spacing_mm.y, g.spacing_mm.z);
    out["origin"] = py::make_tuple(g.origin_mm.x, g.origin_mm.y, g.origin_mm.z);
  }
  out["sidecar"] = native->sidecar;
  out["native"] = native;
  return out;
}

struct GenerateArgs {
  std::string file, text, name;
  std::optional<std::uint64_t> seed;
  std::optional<std::vector<std::string>> profiles;
  std::uint64_t memory_limit = 0;
  std::string out;  // also write the CLI's files here
  bool force = false;
  std::string command_line;
};

py::dict generate(const GenerateArgs& a, int threads) {
  struct Made {
    SampleCapture capture;
    SampleSummary summary;
    std::uint64_t seed;
  };
  Made made = runReleased<Made>(
      [&](const Cancel& cancelled) {
        Made m;
        Scenario sc = readScenario(a.file, a.text, a.name);
        SampleRequest req;
        req.scenario = &sc;
        std::random_device rd;
        req.seed = a.seed ? *a.seed : sc.seed ? *sc.seed : ((std::uint64_t(rd()) << 32) ^ rd()) & ((1ULL << 53) - 1);
        m.seed = req.seed;
        req.gxl_dialect = sc.gxl_dialect;
        req.command_line = a.command_line;
        req.memory_limit = a.memory_limit ? a.memory_limit : defaultMemoryLimitBytes();
        if (a.profiles) {
          req.profiles.emplace();
          for (const auto& p : *a.profiles) req.profiles->push_back(loadProfile(p, "profiles", 0));
        }
        req.capture = &m.capture;
        req.cancelled = cancelled;
        if (a.out.empty()) {
          req.write_files = false;
          m.summary = generateSample(req, {});
        } else {
          std::vector<std::filesystem::path> inputs = scenarioInputs(sc);
          StagedDirectory dir(a.out, a.force ? ExistingOutput::ReplaceOwn : ExistingOutput::Refuse, inputs, "out");
          m.summary = generateSample(req, dir.path());
          dir.commit();
        }
        return m;
      },
      threads);
  py::dict out = sampleDict(std::move(made.capture), made.summary);
  out["seed"] = made.seed;
  return out;
}

// The truth of a sample in memory written as `generate` writes it (mask, centreline, radius,
// classes, the graph's CSV and key points, sample.json), for the scorer, which reads files.
void writeTruth(const NativeSample& s, const py::dict& volumes, const std::filesystem::path& dir) {
  if (!s.has_grid) throw InputError("", 0, "the sample has no volumes to score against; allowed: a sample made with [image] enabled");
  std::vector<Channel> channels;
  std::vector<py::array> keep;
  for (const char* role : {"mask", "centerline", "radius", "classes", "instances"}) {
    if (!volumes.contains(role)) continue;
    py::array a = volumes[role].cast<py::array>();
    VoxelType type = VoxelType::Float32;
    if (a.dtype().is(py::dtype::of<std::uint8_t>()))
      type = VoxelType::UInt8;
    else if (a.dtype().is(py::dtype::of<std::uint32_t>()))
      type = VoxelType::UInt32;
    else if (a.dtype().is(py::dtype::of<std::uint16_t>()))
      type = VoxelType::UInt16;
    keep.push_back(py::array::ensure(a, py::array::f_style));
    channels.push_back(
        Channel{role, VolumeView{&s.grid, keep.back().data(), type, std::string(role) != "radius" && std::string(role) != "centerline", ""}});
  }
  nlohmann::ordered_json files;
  writeChannels(channels, {"nifti"}, dir, files);
  writeGraphFiles(s.forest.vessels, s.forest.trees, s.grid, {"csv"}, "", dir, files);
  std::ofstream(dir / "sample.json") << s.sidecar << "\n";
}

// Writes a prediction array on the truth's grid as NIfTI (voxels > 0 are vessel).
void writePrediction(const py::array& prediction, const std::filesystem::path& mask_file, const std::filesystem::path& out) {
  const NiftiVolume truth = readNiftiVolume(mask_file, defaultMemoryLimitBytes(), 1, "the truth mask");
  const auto& g = truth.values.grid;
  if (prediction.ndim() != 3 || prediction.shape(0) != g.dims[0] || prediction.shape(1) != g.dims[1] || prediction.shape(2) != g.dims[2])
    throw InputError("prediction", 0,
                     "has shape " +
                         std::string(py::str(py::make_tuple(prediction.shape(0), prediction.ndim() > 1 ? prediction.shape(1) : 0,
                                                            prediction.ndim() > 2 ? prediction.shape(2) : 0))) +
                         "; allowed: the truth's shape (" + std::to_string(g.dims[0]) + ", " + std::to_string(g.dims[1]) + ", " +
                         std::to_string(g.dims[2]) + "), indexed (x, y, z)");
  auto values = py::array_t<float, py::array::f_style | py::array::forcecast>::ensure(prediction);
  Volume<std::uint8_t> v;
  v.grid = g;
  v.data.assign(static_cast<std::size_t>(g.voxelCount()), 0);
  const float* p = values.data();
  for (std::size_t i = 0; i < v.data.size(); ++i) v.data[i] = p[i] > 0 ? 1 : 0;
  writeNifti(out, viewOf(v, true, "angiosynth.score prediction"));
}

// The surface of a sample's forest (as [mesh] makes it during generate) into a new directory, with
// mesh.json as `angiosynth mesh` writes it; returns mesh.json's JSON.
std::string writeMesh(const NativeSample& s, const std::string& settings_toml, const std::filesystem::path& out, bool force, int threads) {
  return runReleased<std::string>(
      [&](const Cancel&) {
        toml::table root;
        try {
          root = toml::parse(settings_toml, std::string("<mesh settings>"));
        } catch (const toml::parse_error& e) {
          throw InputError("<mesh settings>", static_cast<int>(e.source().begin.line),
                           std::string("not valid TOML: ") + std::string(e.description()));
        }
        const double voxel_mm = s.has_grid ? s.grid.spacing_mm.x : 1.0;
        const MeshParameters p = readMeshParameters(root, "<mesh settings>", voxel_mm);
        StagedDirectory dir(out, force ? ExistingOutput::ReplaceOwn : ExistingOutput::Refuse, {}, "directory");
        std::vector<std::string> kinds;
        for (const auto& t : s.forest.trees) kinds.push_back(t.kind);
        const auto surface = writeSurfaceFiles(s.forest.vessels, p, defaultMemoryLimitBytes(), dir.path(), {}, kinds);
        const nlohmann::ordered_json j = {{"tool", "angiosynth " + std::string(kVersion)},
                                          {"input", "a sample in memory (Python)"},
                                          {"parameters", surface.parameters},
                                          {"statistics", surface.statistics.toJson()},
                                          {"files", surface.files}};
        std::ofstream(dir.path() / "mesh.json") << j.dump(2) << '\n';
        dir.commit();
        return j.dump();
      },
      threads);
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "angiosynth's native pipeline (use the angiosynth package, not this module)";
  m.attr("version") = kVersion;
  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) { PyErr_SetString(input_error.ptr(), e.what()); }
  });
  py::class_<NativeSample, std::shared_ptr<NativeSample>>(m, "NativeSample");

  m.def(
      "generate",
      [](const std::string& file, const std::string& text, const std::string& name, std::optional<std::uint64_t> seed,
         std::optional<std::vector<std::string>> profiles, int threads, std::uint64_t memory_limit, const std::string& out, bool force,
         const std::string& command_line) {
        return generate(GenerateArgs{file, text, name, seed, profiles, memory_limit, out, force, command_line}, threads);
      },
      py::arg("file"), py::arg("text"), py::arg("name"), py::arg("seed"), py::arg("profiles"), py::arg("threads"), py::arg("memory_limit"),
      py::arg("out"), py::arg("force"), py::arg("command_line"));

  py::class_<DatasetSpec, std::shared_ptr<DatasetSpec>>(m, "DatasetSpec")
      .def(py::init([](const std::filesystem::path& file) { return std::make_shared<DatasetSpec>(readDatasetSpec(file)); }))
      .def_readonly("file", &DatasetSpec::file)
      .def_readonly("name", &DatasetSpec::name)
      .def_readonly("id", &DatasetSpec::id)
      .def_readonly("samples", &DatasetSpec::samples)
      .def_readonly("seed", &DatasetSpec::seed)
      .def_readonly("labels", &DatasetSpec::labels)
      .def_readonly("kinds", &DatasetSpec::kinds)
      .def_readonly("label_policy", &DatasetSpec::label_policy)
      .def_readonly("channel_name", &DatasetSpec::channel_name)
      .def("dataset_dir_name", [](const DatasetSpec& s) { return datasetDirName(s); })
      .def("sample_id", [](const DatasetSpec& s, std::int64_t i) { return sampleId(s, i); })
      .def("label_values", [](const DatasetSpec& s) { return labelValues(s).dump(); })
      .def(
          "sample",
          [](const DatasetSpec& spec, std::int64_t index, int threads, std::uint64_t memory_limit) {
            DatasetSampleInMemory made = runReleased<DatasetSampleInMemory>(
                [&](const Cancel& cancelled) {
                  return datasetSampleInMemory(spec, index, memory_limit ? memory_limit : defaultMemoryLimitBytes(), cancelled);
                },
                threads);
            py::dict out = sampleDict(std::move(made.capture), made.summary);
            out["seed"] = made.resolved.seed;
            out["id"] = made.resolved.id;
            out["profile"] = made.resolved.profile;
            out["parameters_toml"] = made.resolved.toml;
            out["image_role"] = made.image_role;
            out["label_role"] = made.label_role;
            return out;
          },
          py::arg("index"), py::arg("threads") = 0, py::arg("memory_limit") = 0);

  m.def(
      "segment",
      [](const py::array& image, const std::array<double, 3>& spacing, const SegmentOptions& options, int threads) {
        if (image.ndim() != 3) throw InputError("image", 0, "has " + std::to_string(image.ndim()) + " dimensions; allowed: 3, indexed (x, y, z)");
        VolumeGrid g;
        for (int a = 0; a < 3; ++a) g.dims[a] = static_cast<std::int32_t>(image.shape(a));
        g.spacing_mm = Vec3(spacing[0], spacing[1], spacing[2]);
        if (!(spacing[0] > 0 && spacing[1] > 0 && spacing[2] > 0)) throw InputError("spacing", 0, "must be > 0 mm on every axis");
        const auto values = py::array_t<float, py::array::f_style | py::array::forcecast>::ensure(image);
        Volume<float> v(g);
        std::copy(values.data(), values.data() + g.voxelCount(), v.data.begin());
        struct Made {
          Volume<std::uint8_t> mask;
          Volume<float> response;
          SegmentSummary summary;
        };
        Made made = runReleased<Made>(
            [&](const Cancel&) {
              Made m;
              try {
                m.mask = segment(v, options, m.summary, &m.response);
              } catch (const std::invalid_argument& e) { throw InputError("segment", 0, e.what()); }
              return m;
            },
            threads);
        const std::vector<py::ssize_t> shape{g.dims[0], g.dims[1], g.dims[2]};
        py::array_t<std::uint8_t, py::array::f_style> mask(shape);
        py::array_t<float, py::array::f_style> response(shape);
        std::copy(made.mask.data.begin(), made.mask.data.end(), mask.mutable_data());
        std::copy(made.response.data.begin(), made.response.data.end(), response.mutable_data());
        py::dict summary;
        summary["method"] = made.summary.method;
        summary["sigmas_voxels"] = made.summary.sigmas_voxels;
        summary["threshold"] = made.summary.threshold;
        summary["max_response"] = made.summary.max_response;
        summary["voxels"] = made.summary.voxels;
        summary["seconds"] = made.summary.seconds;
        return py::make_tuple(mask, response, summary);
      },
      py::arg("image"), py::arg("spacing"), py::arg("options"), py::arg("threads") = 0);
  py::class_<SegmentOptions>(m, "SegmentOptions")
      .def(py::init<>())
      .def_readwrite("method", &SegmentOptions::method)
      .def_readwrite("sigmas_mm", &SegmentOptions::sigmas_mm)
      .def_readwrite("bright", &SegmentOptions::bright)
      .def_readwrite("alpha", &SegmentOptions::alpha)
      .def_readwrite("beta", &SegmentOptions::beta)
      .def_readwrite("gamma", &SegmentOptions::gamma)
      .def_readwrite("tau", &SegmentOptions::tau)
      .def_readwrite("threshold_fraction", &SegmentOptions::threshold_fraction)
      .def_readwrite("has_threshold", &SegmentOptions::has_threshold)
      .def_readwrite("threshold", &SegmentOptions::threshold);

  m.def("write_truth", [](const NativeSample& s, const py::dict& volumes, const std::filesystem::path& dir) { writeTruth(s, volumes, dir); });
  m.def("write_prediction", &writePrediction);
  m.def("write_mesh", &writeMesh, py::arg("native"), py::arg("settings"), py::arg("out"), py::arg("force") = false, py::arg("threads") = 0);
  m.def(
      "score",
      [](const std::filesystem::path& prediction, const std::filesystem::path& truth, bool topcow, std::optional<double> tolerance_mm,
         std::optional<std::vector<double>> bins_voxels, std::optional<std::vector<double>> bins_mm, std::optional<std::string> label_scheme,
         std::optional<std::map<int, std::string>> legend, int threads) {
        ScoreOptions opt;
        if (topcow) opt.conventions = ScoreConventions::TopCoW;
        opt.tolerance_mm = tolerance_mm;
        if (bins_voxels) opt.bins_voxels = *bins_voxels;
        if (bins_mm) opt.bins_mm = *bins_mm;
        if (label_scheme) opt.scheme = labelScheme(*label_scheme);
        opt.memory_limit = defaultMemoryLimitBytes();
        // A sample directory, or a plain annotation (a NIfTI file, binary or labelled).
        TruthFiles files = std::filesystem::is_directory(truth) ? sampleTruth(truth) : annotationTruth(truth);
        if (legend) files.legend = *legend;
        return runReleased<std::string>([&](const Cancel&) { return scoreCase(prediction, files, opt).toJson().dump(); }, threads);
      },
      py::arg("prediction"), py::arg("truth"), py::arg("topcow") = false, py::arg("tolerance_mm") = std::nullopt,
      py::arg("bins_voxels") = std::nullopt, py::arg("bins_mm") = std::nullopt, py::arg("label_scheme") = std::nullopt,
      py::arg("legend") = std::nullopt, py::arg("threads") = 0);
}
