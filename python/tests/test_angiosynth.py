"""The Python module against the program's own files, read by nibabel and networkx."""

import csv
import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import networkx as nx
import nibabel as nib
import numpy as np
import pytest

import angiosynth

# A small CCO forest of two kinds, with a profile and the CSV graph: every kind of volume.
SMALL = {
    "seed": 4,
    "domain": {"shape": "sphere", "radius": "6 mm", "voxel_size": "0.25 mm"},
    "tree": {
        "method": "cco",
        "terminals": 60,
        "inlet": [{"kind": "artery", "root_offset": [-1.5, 5.8, 0]}, {"kind": "vein", "root_offset": [1.5, 5.8, 0]}],
    },
    "physics": {"perfusion_pressure": "100 mmHg", "terminal_pressure": "60 mmHg", "perfusion_flow": "10 mL/min"},
    "image": {"voxel_size": "0.25 mm", "supersampling": 2, "graph_formats": ["csv"]},
    "degrade": {"profiles": ["cta"]},
}


def run(program, *args, cwd=None):
    done = subprocess.run([program, *args], cwd=cwd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def nifti(path):
    img = nib.load(str(path))
    return np.asanyarray(img.dataobj), img.affine


def test_every_channel_equals_the_programs_file(program, tmp_path):
    params = tmp_path / "small.toml"
    params.write_text(angiosynth._toml_text(SMALL))
    sample = angiosynth.generate(SMALL)
    run(program, "generate", str(params), "--out", str(tmp_path / "cli"), "--quiet")
    files = json.loads((tmp_path / "cli/sample.json").read_text())["files"]
    assert set(sample.volumes) == {r for r, f in files.items() if f.endswith(".nii.gz")}
    for role, array in sample.volumes.items():
        data, affine = nifti(tmp_path / "cli" / files[role])
        assert array.dtype == data.dtype, role
        assert np.array_equal(array, data), role
        assert np.allclose(sample.affine, affine), role
    assert sample.seed == 4
    assert sample.statistics == json.loads((tmp_path / "cli/sample.json").read_text())["statistics"]
    assert sample.classes_legend == {0: "background", 1: "artery", 2: "vein"}
    # The graph's columns are the CSV's rows.
    with open(tmp_path / "cli/edges.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(sample.graph)
    for col in ("id", "node1id", "node2id"):
        assert [int(r[col]) for r in rows] == list(sample.graph.edges[col])
    for col in ("length", "radius", "flow", "volume"):
        assert [float(r[col]) for r in rows] == list(sample.graph.edges[col])
    assert [r["kind"] for r in rows] == sample.graph.edges["kind"]


def test_write_gives_the_programs_files(program, tmp_path):
    params = tmp_path / "small.toml"
    params.write_text(angiosynth._toml_text(SMALL))
    sample = angiosynth.generate(params)
    sample.write(tmp_path / "py")
    run(program, "generate", str(params), "--out", str(tmp_path / "cli"), "--quiet")
    cli = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert sorted(p.name for p in (tmp_path / "py").iterdir()) == cli
    for name in cli:
        if name in ("sample.json", ".angiosynth-files.json"):
            continue  # the command line and timings differ
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # An existing output is refused, as the program refuses it.
    with pytest.raises(angiosynth.InputError, match="out"):
        sample.write(tmp_path / "py")


def test_spec_items_equal_the_datasets_files(program, source, tmp_path):
    spec_file = source / "tests/data/dataset_av.toml"  # distributions, labels by kind, a warping profile
    run(program, "dataset", str(spec_file), "--out", str(tmp_path), "--quiet")
    spec = angiosynth.Spec(spec_file)
    root = tmp_path / "Dataset903_ArteryVeinTiny"
    assert len(spec) == 3
    warped = 0
    for i in range(len(spec)):
        s = spec[i]
        assert s.id == spec.sample_id(i)
        image, affine = nifti(root / f"imagesTr/{s.id}_0000.nii.gz")
        label, _ = nifti(root / f"labelsTr/{s.id}.nii.gz")
        assert np.array_equal(s.image, image) and s.image.dtype == image.dtype
        assert np.array_equal(s.label, label) and s.label.dtype == label.dtype
        assert np.allclose(s.affine, affine)
        for role in ("mask", "centerline", "radius", "instances"):  # (classes went to labelsTr)
            truth, _ = nifti(root / f"groundtruth/{s.id}/{role}.nii.gz")
            assert np.array_equal(s.volumes[role], truth), (i, role)
        warped += s.image_role == "image_profile_warp"
    assert warped >= 1, "the spec's draws should give at least one warped sample"


def test_a_spec_sample_is_the_same_whatever_the_threads(source):
    one = angiosynth.Spec(source / "tests/data/dataset_tiny.toml", threads=1)[2]
    two = angiosynth.Spec(source / "tests/data/dataset_tiny.toml", threads=2)[2]
    for role in one.volumes:
        assert np.array_equal(one.volumes[role], two.volumes[role]), role


def test_graph_to_networkx_is_a_forest_of_the_trees():
    s = angiosynth.generate(SMALL)
    g = s.graph.to_networkx()
    assert g.number_of_nodes() == len(s.graph.nodes["id"]) and g.number_of_edges() == len(s.graph)
    assert nx.is_forest(g.to_undirected())
    assert nx.number_weakly_connected_components(g) == len(s.trees) == 2
    # Flow is conserved at every bifurcation: a parent carries its daughters' flow.
    for n in g.nodes:
        out = list(g.out_edges(n, data=True))
        into = list(g.in_edges(n, data=True))
        if len(out) == 2 and into:
            assert abs(into[0][2]["flow"] - out[0][2]["flow"] - out[1][2]["flow"]) <= 1e-9 * into[0][2]["flow"]


def test_score_agrees_with_the_program(program, tmp_path):
    params = tmp_path / "small.toml"
    params.write_text(angiosynth._toml_text(SMALL))
    s = angiosynth.generate(params, out=tmp_path / "sample")
    perfect = angiosynth.score(s.mask, s)
    assert perfect["overlap"]["dice"] == 1.0
    # A prediction that misses the thinnest vessels: the same numbers from memory and from the files.
    pred = (s.mask > 0) & ~((s.radius > 0) & (s.radius < 0.15))
    pred_file = tmp_path / "pred.nii.gz"
    nib.save(nib.Nifti1Image(pred.astype(np.uint8), s.affine), str(pred_file))
    run(program, "score", str(pred_file), str(tmp_path / "sample"), "--out", str(tmp_path / "scores.json"))
    cli = json.loads((tmp_path / "scores.json").read_text())
    mine = angiosynth.score(pred, s)
    for block in ("overlap", "centreline", "cldice", "calibre", "topology"):
        assert mine[block] == cli[block], block
    assert angiosynth.score(pred_file, tmp_path / "sample")["overlap"] == cli["overlap"]
    # A plain annotation: the sample's mask as a NIfTI file scores the overlap alike, with no centreline metrics.
    plain = angiosynth.score(pred, tmp_path / "sample/mask.nii.gz")
    assert plain["overlap"] == cli["overlap"] and "centreline" not in plain


def test_bad_input_raises_the_programs_message(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[domain]\nshape = \"sphere\"\nradius = \"6 mm\"\nvoxel_size = \"0.25 mm\"\n\n[tree]\nmethod = \"cco\"\nterminals = -3\n")
    with pytest.raises(angiosynth.InputError, match=r"bad.toml:8: .*terminals"):
        angiosynth.generate(bad)
    with pytest.raises(angiosynth.InputError, match=r"<string>:1: not valid TOML"):
        angiosynth.generate("[tree\nterminals = 5\n")
    with pytest.raises(angiosynth.InputError, match="no such parameter file"):
        angiosynth.generate("no_such_file.toml")
    with pytest.raises(ValueError):  # InputError is a ValueError
        angiosynth.Spec(tmp_path / "bad.toml")
    with pytest.raises(angiosynth.InputError, match="shape"):
        angiosynth.score(np.zeros((3, 3, 3)), angiosynth.generate(SMALL))


def test_ctrl_c_returns_promptly_and_stops_the_work(tmp_path):
    # A growth of minutes, interrupted after a second: KeyboardInterrupt within a second, and the
    # process uses no more CPU afterwards (no thread left working).
    script = tmp_path / "long.py"
    script.write_text(textwrap.dedent(f"""
        import sys, time, os
        sys.path.insert(0, {str(angiosynth.__file__.rsplit('/angiosynth/', 1)[0])!r})
        import angiosynth
        params = {{"domain": {{"shape": "sphere", "radius": "20 mm", "voxel_size": "0.2 mm"}},
                  "tree": {{"method": "cco", "terminals": 400000}},
                  "physics": {{"perfusion_pressure": "100 mmHg", "terminal_pressure": "60 mmHg", "perfusion_flow": "500 mL/min"}},
                  "image": {{"enabled": False}}}}
        print("started", flush=True)
        try:
            angiosynth.generate(params, seed=1)
        except KeyboardInterrupt:
            t = time.monotonic()
            cpu = time.process_time()
            time.sleep(1.0)
            print("interrupted", time.process_time() - cpu, flush=True)
    """))
    p = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "started"
    time.sleep(2.0)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    line = p.stdout.readline().split()
    assert line and line[0] == "interrupted", p.stderr.read()
    assert time.monotonic() - sent < 3.0  # 1 s of it is the script's own sleep
    assert float(line[1]) < 0.05, "CPU was used after the interrupt returned"
    assert p.wait(timeout=10) == 0


def test_the_docs_python_blocks_run(source, tmp_path, monkeypatch):
    # Every ```python block of docs/python.md and the README, in order, in one namespace, in a
    # directory laid out like the source tree.
    for d in ("examples", "demand_maps", "noise_profiles"):
        (tmp_path / d).symlink_to(source / d)
    monkeypatch.chdir(tmp_path)
    for page in ("docs/python.md", "README.md"):
        text = (source / page).read_text()
        blocks = [b.split("```", 1)[0] for b in text.split("```python\n")[1:]]
        assert blocks, page
        namespace = {}
        for block in blocks:
            exec(compile(block, f"{page} block", "exec"), namespace)


def test_iterate_gives_the_samples_in_order(source):
    spec = angiosynth.Spec(source / "tests/data/dataset_tiny.toml")
    made = list(spec.iterate([4, 1, 2], in_flight=2))
    assert [s.id for s in made] == [spec.sample_id(i) for i in (4, 1, 2)]
    assert np.array_equal(made[1].image, spec[1].image)


def test_mesh_of_a_sample_in_memory_is_the_surface_generate_writes(program, tmp_path):
    with_mesh = dict(SMALL, mesh={"formats": ["stl"]})
    params = tmp_path / "mesh.toml"
    params.write_text(angiosynth._toml_text(with_mesh))
    run(program, "generate", str(params), "--out", str(tmp_path / "cli"), "--quiet")
    info = angiosynth.generate(SMALL).mesh(tmp_path / "py", formats=["stl"])
    assert (tmp_path / "py/surface.stl").read_bytes() == (tmp_path / "cli/surface.stl").read_bytes()
    st = info["statistics"]
    assert st["boundary_edges"] == 0 and st["nonmanifold_edges"] == 0 and st["trees"] == 2
    assert st["tree_euler_characteristic"] == [2, 2]  # each tree's surface a sphere: closed, no handle
    with pytest.raises(angiosynth.InputError, match="formats"):
        angiosynth.generate(SMALL).mesh(tmp_path / "bad", formats=["xyz"])


def test_segment_gives_the_programs_mask_and_response(program, tmp_path):
    sample = angiosynth.generate(SMALL)
    image = sample.images["cta"]
    path = tmp_path / "image.nii.gz"
    nib.save(nib.Nifti1Image(np.asarray(image, dtype=np.float32), sample.affine), str(path))
    run(program, "segment", str(path), "--method", "frangi", "--sigmas", "0.25,0.5", "--out", str(tmp_path / "m.nii.gz"),
        "--response", str(tmp_path / "r.nii.gz"), "--quiet")
    mask, response, summary = angiosynth.segment(image, sample.spacing, method="frangi", sigmas_mm=[0.25, 0.5])
    assert mask.shape == image.shape and mask.dtype == np.uint8
    assert np.array_equal(mask, nifti(tmp_path / "m.nii.gz")[0])
    assert np.array_equal(response, nifti(tmp_path / "r.nii.gz")[0])
    assert summary["voxels"] == int(mask.sum()) > 0
    # Dark vessels: the negated image gives the same mask.
    dark, _, _ = angiosynth.segment(-np.asarray(image, dtype=np.float32), sample.spacing, method="frangi", sigmas_mm=[0.25, 0.5], dark=True)
    assert np.array_equal(mask, dark)
    with pytest.raises(ValueError, match="allowed: otsu, frangi, sato, jerman"):
        angiosynth.segment(image, sample.spacing, method="watershed")
