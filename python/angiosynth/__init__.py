"""angiosynth: synthetic vascular trees and angiography volumes with exact ground truth, in memory.

    import angiosynth
    s = angiosynth.generate("examples/vascusynth_like.toml", seed=7)
    s.image, s.mask, s.centerline, s.radius      # NumPy arrays indexed (x, y, z), as nibabel reads the files
    s.images["cta"]                              # the image of each degradation profile
    s.affine                                     # voxel (i, j, k) -> world mm (RAS+), as in the NIfTI files
    s.graph.to_networkx()                        # the vessel graph with its attributes
    s.write("out/sample")                        # the files `angiosynth generate` writes

    spec = angiosynth.Spec("examples/dataset_small.toml")
    spec[3]                                      # sample 3 exactly as `angiosynth dataset` writes it
    angiosynth.score(prediction, s)              # the metrics of `angiosynth score`

Every call releases the GIL while it works; Ctrl-C stops it at its next progress point. Errors in
the input raise angiosynth.InputError (a ValueError) with the program's `file:line: what is wrong,
what is allowed` text. `angiosynth.torch.SyntheticVessels` is a PyTorch dataset over a Spec.
"""

from __future__ import annotations

import json
import os
import shlex
import sys
import tempfile
from typing import Any, Mapping

import numpy as np

from . import _core
from ._core import InputError

__all__ = ["generate", "Sample", "Graph", "Spec", "score", "segment", "InputError", "__version__"]
__version__ = _core.version


def _toml_value(v: Any, where: str) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    if isinstance(v, str):
        return json.dumps(v)  # a TOML basic string is a JSON string
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x, where) for x in v) + "]"
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{json.dumps(str(k))} = {_toml_value(x, where + '.' + str(k))}" for k, x in v.items()) + "}"
    raise InputError(f"params: {where} is a {type(v).__name__}; allowed: numbers, strings, booleans, lists and dicts")


def _toml_text(params: Mapping[str, Any]) -> str:
    """A dict of parameters as TOML: top-level scalars first, then one [table] per dict and one [[table]] per list of dicts."""
    lines, tables = [], []
    for k, v in params.items():
        if isinstance(v, Mapping):
            tables.append((k, v, False))
        elif isinstance(v, (list, tuple)) and v and all(isinstance(x, Mapping) for x in v):
            tables.append((k, v, True))
        else:
            lines.append(f"{json.dumps(str(k))} = {_toml_value(v, str(k))}")
    for name, value, array in tables:
        for table in value if array else [value]:
            lines.append("")
            lines.append(f"[[{json.dumps(str(name))}]]" if array else f"[{json.dumps(str(name))}]")
            for k, v in table.items():
                lines.append(f"{json.dumps(str(k))} = {_toml_value(v, f'{name}.{k}')}")
    return "\n".join(lines) + "\n"


def _parameters(params: Any) -> tuple[str, str, str]:
    """(file, text, name) for the native reader: a path, TOML text, or a dict."""
    if isinstance(params, Mapping):
        return "", _toml_text(params), "<dict>"
    if isinstance(params, os.PathLike):
        return os.fspath(params), "", ""
    if isinstance(params, str):
        if "\n" in params or "=" in params:
            return "", params, "<string>"
        return params, "", ""
    raise TypeError(f"params is a {type(params).__name__}; allowed: a parameter file's path, TOML text, or a dict")


class Graph:
    """The vessel graph as the CSV export writes it: `nodes` and `edges`, each a dict of equal-length columns.

    nodes: id, pos_x, pos_y, pos_z (mm), type, pressure (Pa), radius (mm), tree_index, tree, kind.
    edges: id (the segment's distal node), node1id, node2id, length (mm), radius (mm), flow (mm^3/s),
    volume (mm^3), tree_index, tree, kind, class; with stages: stage, role, branching; with tapers
    or walls: radius_start, wall_start, wall.
    """

    def __init__(self, columns: dict):
        self.nodes: dict = columns["nodes"]
        self.edges: dict = columns["edges"]

    def __len__(self) -> int:
        return len(self.edges["id"])

    def to_networkx(self):
        """A networkx.DiGraph (parent to child) with every column as a node or edge attribute."""
        import networkx as nx

        g = nx.DiGraph()
        names = list(self.nodes)
        for row in zip(*(self.nodes[k] for k in names)):
            attrs = {k: (v.item() if hasattr(v, "item") else v) for k, v in zip(names, row)}
            g.add_node(attrs.pop("id"), **attrs)
        names = list(self.edges)
        for row in zip(*(self.edges[k] for k in names)):
            attrs = {k: (v.item() if hasattr(v, "item") else v) for k, v in zip(names, row)}
            g.add_edge(attrs["node1id"], attrs["node2id"], **attrs)
        return g

    def __repr__(self) -> str:
        return f"Graph({len(self.nodes['id'])} nodes, {len(self)} segments)"


class Sample:
    """One generated sample in memory.

    volumes     every volume by its role, the stem of the file the program writes it to: image, mask,
                centerline, radius, instances, classes, label, image_<profile>, and for a profile that
                warps mask_<profile>, ... ; arrays indexed (x, y, z) over the module's own memory
    image       the clean image;  images: the image of each profile by profile name
    affine      voxel (i, j, k) to world mm (RAS+, voxel centres), as in the NIfTI files
    graph       the vessel graph (Graph);  warped_graphs: the graph of each warping profile
    statistics, parameters, trees, classes_legend, sidecar: what sample.json holds
    seed        the seed it was grown with
    """

    def __init__(self, made: dict, request: dict | None):
        self.volumes: dict[str, np.ndarray] = made["volumes"]
        self.seed: int = made["seed"]
        self.sidecar: dict = json.loads(made["sidecar"])
        self.graph = Graph(made["graph"])
        self.warped_graphs = {k: Graph(v) for k, v in made["warped_graphs"].items()}
        self.shape = tuple(made["dims"]) if "dims" in made else None
        self.spacing = tuple(made["spacing"]) if "dims" in made else None
        self.origin = tuple(made["origin"]) if "dims" in made else None
        self._native = made["native"]
        self._request = request

    def __getitem__(self, role: str) -> np.ndarray:
        return self.volumes[role]

    def _volume(self, role: str):
        return self.volumes.get(role)

    image = property(lambda self: self._volume("image"), doc="the clean image")
    mask = property(lambda self: self._volume("mask"), doc="1 where a vessel covers a voxel's centre region (partial volume above half)")
    centerline = property(lambda self: self._volume("centerline"), doc="the exact centreline voxels")
    radius = property(lambda self: self._volume("radius"), doc="the vessel radius in mm on the centreline")
    instances = property(lambda self: self._volume("instances"), doc="the segment id of each vessel voxel")
    classes = property(lambda self: self._volume("classes"), doc="the class of each vessel voxel (classes_legend)")
    label = property(lambda self: self._volume("label"), doc="the training label of the [image] label_policy, where it differs from the mask")

    @property
    def images(self) -> dict[str, np.ndarray]:
        """The degraded image of each profile, by profile name."""
        return {role[len("image_"):]: v for role, v in self.volumes.items() if role.startswith("image_")}

    @property
    def affine(self) -> np.ndarray:
        a = np.eye(4)
        if self.spacing is not None:
            a[:3, :3] = np.diag(self.spacing)
            a[:3, 3] = self.origin
        return a

    statistics = property(lambda self: self.sidecar.get("statistics", {}))
    parameters = property(lambda self: self.sidecar.get("parameters", {}))
    trees = property(lambda self: self.sidecar.get("trees", []))

    @property
    def classes_legend(self) -> dict[int, str]:
        return {int(k): v for k, v in self.sidecar.get("classes", {}).items()}

    def write(self, directory: str | os.PathLike, force: bool = False) -> str:
        """Writes the files `angiosynth generate` writes for this sample (every format its
        parameters ask for, sample.json, previews, meshes when [mesh] is on) into a new directory.
        The sample is made again through the program's writers from the same parameters and seed,
        so the files are those the program writes, byte for byte."""
        if self._request is None:
            raise InputError("this sample came from a dataset spec; write the dataset with `angiosynth dataset`")
        r = dict(self._request, seed=self.seed, out=os.fspath(directory), force=force)
        _core.generate(**r)
        return os.fspath(directory)

    def mesh(self, directory: str | os.PathLike, force: bool = False, threads: int = 0, **settings) -> dict:
        """The closed surface of the sample's vessels, as `angiosynth mesh` makes it, written into a
        new directory (surface.<format> and mesh.json); settings are the keys of [mesh]
        (docs/parameters.md), e.g. formats=["stl", "vtp"], ends="capped". Returns mesh.json as a dict."""
        text = _toml_text({"mesh": settings}) if settings else "[mesh]\n"
        return json.loads(_core.write_mesh(self._native, text, os.fspath(directory), force=force, threads=threads))

    def __repr__(self) -> str:
        return f"Sample(seed={self.seed}, shape={self.shape}, volumes={sorted(self.volumes)}, {self.graph!r})"


def generate(
    params: Any,
    seed: int | None = None,
    *,
    profiles: list[str] | None = None,
    threads: int = 0,
    memory_limit: int | None = None,
    out: str | os.PathLike | None = None,
    force: bool = False,
) -> Sample:
    """Grows one sample and makes its volumes and graph in memory.

    params        a parameter file (.toml, or VascuSynth's format), TOML text, or a dict of tables
    seed          the random seed (default: the file's seed, else a fresh one: Sample.seed tells)
    profiles      degradation profiles instead of the file's [degrade] profiles ([] for the clean image only)
    threads       TBB threads (0: every core)
    memory_limit  bytes (default: 75 % of physical memory); a sample that needs more is refused before it starts
    out           also write the program's files into this new directory (in the same pass)
    """
    file, text, name = _parameters(params)
    request = dict(
        file=file,
        text=text,
        name=name,
        profiles=profiles,
        threads=threads,
        memory_limit=memory_limit or 0,
        command_line="python: angiosynth.generate(" + (shlex.quote(file) if file else name) + ")",
    )
    made = _core.generate(**request, seed=seed, out=os.fspath(out) if out else "", force=force)
    return Sample(made, request)


class Spec:
    """A dataset spec: spec[i] is sample i exactly as `angiosynth dataset` writes it, in memory.

    The sample's volumes are all there (Sample.volumes); `image` and `label` of the returned sample
    are what imagesTr and labelsTr hold for it. Sample i depends on the spec and i alone: any
    process, thread count or order gives the same arrays.
    """

    def __init__(self, path: str | os.PathLike, threads: int = 0, memory_limit: int | None = None):
        self._spec = _core.DatasetSpec(os.fspath(path))
        self.path = os.fspath(path)
        self.threads = threads
        self.memory_limit = memory_limit or 0

    name = property(lambda self: self._spec.name)
    seed = property(lambda self: self._spec.seed)
    labels = property(lambda self: self._spec.labels, doc="'binary' or 'kind'")
    label_policy = property(lambda self: self._spec.label_policy)

    @property
    def label_values(self) -> dict:
        return json.loads(self._spec.label_values())

    def sample_id(self, index: int) -> str:
        return self._spec.sample_id(index)

    def __len__(self) -> int:
        return self._spec.samples

    def __getitem__(self, index: int) -> "DatasetSample":
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        index = int(index)
        if index < 0:
            index += len(self)
        made = self._spec.sample(index, threads=self.threads, memory_limit=self.memory_limit)
        return DatasetSample(made)

    def __iter__(self):
        return self.iterate()

    def iterate(self, indices=None, in_flight: int | None = None):
        """Samples of `indices` (default: all) in order, `in_flight` of them made at once on threads
        of this process (default: one per core, each on one core): the GIL is released while they
        are made, so this uses every core without worker processes."""
        from concurrent.futures import ThreadPoolExecutor

        indices = range(len(self)) if indices is None else list(indices)
        in_flight = in_flight or os.cpu_count() or 1
        threads = self.threads or max(1, (os.cpu_count() or 1) // in_flight)
        make = lambda i: DatasetSample(self._spec.sample(int(i), threads=threads, memory_limit=self.memory_limit))
        with ThreadPoolExecutor(in_flight) as pool:
            pending = []
            for i in indices:
                pending.append(pool.submit(make, i))
                if len(pending) > in_flight:
                    yield pending.pop(0).result()
            for f in pending:
                yield f.result()

    def __getstate__(self):
        return {"path": self.path, "threads": self.threads, "memory_limit": self.memory_limit}

    def __setstate__(self, state):
        self.__init__(state["path"], state["threads"], state["memory_limit"])

    def __repr__(self) -> str:
        return f"Spec({self.path!r}: {self.name}, {len(self)} samples)"


class DatasetSample(Sample):
    """Sample i of a Spec: `image` is the image of imagesTr, `label` that of labelsTr."""

    def __init__(self, made: dict):
        super().__init__(made, None)
        self.id: str = made["id"]
        self.profile: str = made["profile"]
        self.parameters_toml: str = made["parameters_toml"]
        self.image_role: str = made["image_role"]
        self.label_role: str = made["label_role"]

    image = property(lambda self: self.volumes[self.image_role], doc="the image of imagesTr")
    label = property(lambda self: self.volumes[self.label_role], doc="the label of labelsTr")
    clean_image = property(lambda self: self.volumes["image"])


def segment(
    image: Any,
    spacing: tuple[float, float, float] = (1.0, 1.0, 1.0),
    *,
    method: str = "frangi",
    sigmas_mm: list[float] | None = None,
    dark: bool = False,
    alpha: float = 0.5,
    beta: float = 0.5,
    gamma: float = 15.0,
    tau: float = 0.75,
    threshold_fraction: float = 0.02,
    threshold: float | None = None,
    threads: int = 0,
) -> tuple[np.ndarray, np.ndarray, dict]:
    """Segments an image with a reference method, as `angiosynth segment` does (docs/scoring.md).

    image       an array indexed (x, y, z), e.g. a Sample's image or nibabel's dataobj
    spacing     voxel size in mm per axis (scales and Hessians are in mm)
    method      "otsu", "frangi", "sato" or "jerman"
    sigmas_mm   vesselness scales, Gaussian σ in mm (default 1, 2, 3 voxels)
    dark        vessels darker than their surroundings
    threshold_fraction, threshold   the mask: response >= fraction × its maximum, or >= threshold

    Returns (mask uint8, response float32, summary dict), each array indexed (x, y, z).
    """
    options = _core.SegmentOptions()
    options.method = method
    options.sigmas_mm = list(sigmas_mm or [])
    options.bright = not dark
    options.alpha, options.beta, options.gamma, options.tau = alpha, beta, gamma, tau
    options.threshold_fraction = threshold_fraction
    if threshold is not None:
        options.has_threshold, options.threshold = True, float(threshold)
    mask, response, summary = _core.segment(np.asarray(image), tuple(float(s) for s in spacing), options, threads)
    return mask, response, dict(summary)


def score(
    prediction: Any,
    truth: Any,
    *,
    topcow: bool = False,
    tolerance_mm: float | None = None,
    bins_voxels: list[float] | None = None,
    bins_mm: list[float] | None = None,
    label_scheme: str | None = None,
    legend: dict[int, str] | None = None,
    threads: int = 0,
) -> dict:
    """Scores a segmentation as `angiosynth score` does, and returns its results (the JSON it writes) as a dict.

    prediction    a NIfTI file, or an array indexed (x, y, z) on the truth's grid (values > 0 are vessel, above 1 classes)
    truth         a sample directory the program wrote, a Sample in memory, or any NIfTI annotation (binary or labelled)
    topcow        the TopCoW challenge's conventions (26-neighbour borders, 90 mm for an empty mask, 0 for empty ratios)
    label_scheme  class names and challenge metrics: "topcow2024", "topbrain2025-ct" or a JSON file of one
    legend        names of an annotation's class values, {1: "artery", 2: "vein"}
    """
    with tempfile.TemporaryDirectory(prefix="angiosynth-score-") as tmp:
        if isinstance(truth, Sample):
            truth_path = os.path.join(tmp, "truth")
            os.mkdir(truth_path)
            _core.write_truth(truth._native, truth.volumes, truth_path)
        else:
            truth_path = os.fspath(truth)
        # The grid a prediction array is written on: the annotation's, or the sample's mask's.
        reference = truth_path if os.path.isfile(truth_path) else os.path.join(truth_path, "mask.nii.gz")
        if isinstance(prediction, (str, os.PathLike)):
            pred_file = os.fspath(prediction)
        else:
            pred_file = os.path.join(tmp, "prediction.nii.gz")
            _core.write_prediction(np.asarray(prediction), reference, pred_file)
        result = _core.score(pred_file, truth_path, topcow=topcow, tolerance_mm=tolerance_mm, bins_voxels=bins_voxels, bins_mm=bins_mm,
                             label_scheme=label_scheme, legend=legend, threads=threads)
    return json.loads(result)
