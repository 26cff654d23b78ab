"""Independent check of surface meshes angiosynth wrote (VTK from Debian, numpy, scipy).

    check_mesh.py MESH_DIR NODES_CSV EDGES_CSV
    check_mesh.py --ends MESH_DIR
    check_mesh.py --self-intersections MESH_DIR EXT...
    check_mesh.py --wall MESH_DIR NODES_CSV EDGES_CSV THICKNESS_MM [X0,Y0,Z0,X1,Y1,Z1]

Reads surface.stl, .obj, .ply, .vtp with VTK's readers, surface.off by hand and surface.3mf with
the standard library's zipfile and ElementTree (unit millimetre); for each: the
counts of boundary and non-manifold edges (vtkFeatureEdges), duplicate and degenerate faces, the
connected regions with their Euler characteristic (genus), the enclosed volume
(vtkMassProperties) and the signed volume (outward orientation). Estimates the volume of the
union of the tree's capsules by Monte Carlo, independently of the mesher: points drawn
uniformly in each capsule count 1/(capsules holding them). Prints one JSON object.

With --ends MESH_DIR: the cut ends of surface.vtp (VTK's reader) against surface_faces.csv:
per capped end, the largest distance of its cap's points from its plane, its area over πr² and
the smallest cosine between its triangles' normals and the plane's outward normal; the
boundary loops (open ends) with the largest distance of their points from the nearest plane.

With --self-intersections: each surface.EXT as VTK reads it (so with the precision the format
keeps) goes to TetGen (Debian's tetgen), whose -d switch tests every pair of faces for an
intersection with exact predicates; prints {EXT: intersecting pairs}.

With --wall: a hollow wall of constant thickness (surface.vtp, surface_faces.csv; the ends cut
where their nodes are; with a box, clipped to it, and then the lumen's openings: open end rings
and holes in the box's sections): the wall's volume by Monte Carlo (in the box), independently of the mesher (points in
each vessel thickened by the wall, cut by its ends' planes, outside every vessel, counted
1/(thickened vessels holding them)); and the thickness: every vertex of the outer side (farther
than half the wall from the vessels) to the lumen side's triangles (VTK's
vtkImplicitPolyDataDistance), its deviation from the asked thickness in percentiles.
"""
import csv
import json
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import vtk
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree
from vtk.util.numpy_support import vtk_to_numpy


def read_3mf(path):
    """3MF by the standard library (zipfile, ElementTree): every object's mesh, in millimetres."""
    ns = {"m": "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"}
    with zipfile.ZipFile(path) as z:
        assert "[Content_Types].xml" in z.namelist() and "_rels/.rels" in z.namelist()
        rels = ET.fromstring(z.read("_rels/.rels"))
        target = rels[0].get("Target").lstrip("/")
        root = ET.fromstring(z.read(target))
    assert root.get("unit") == "millimeter", root.get("unit")
    pts, faces = [], []
    built = {item.get("objectid") for item in root.find("m:build", ns)}
    for obj in root.find("m:resources", ns).findall("m:object", ns):
        assert obj.get("id") in built, "every object is built"
        mesh = obj.find("m:mesh", ns)
        base = len(pts)
        pts += [[float(v.get(c)) for c in "xyz"] for v in mesh.find("m:vertices", ns)]
        faces += [[base + int(t.get(k)) for k in ("v1", "v2", "v3")] for t in mesh.find("m:triangles", ns)]
    return np.array(pts), np.array(faces)


def read(path):
    ext = path.rsplit(".", 1)[1]
    if ext in ("off", "3mf"):
        if ext == "3mf":
            pts, faces = read_3mf(path)
            nv = len(pts)
        else:
            with open(path) as f:
                assert f.readline().strip() == "OFF"
                nv, nf, _ = map(int, f.readline().split())
                pts = np.array([list(map(float, f.readline().split())) for _ in range(nv)])
                faces = np.array([list(map(int, f.readline().split()))[1:] for _ in range(nf)])
        poly = vtk.vtkPolyData()
        p = vtk.vtkPoints()
        p.SetNumberOfPoints(nv)
        for i, x in enumerate(pts):
            p.SetPoint(i, *x)
        cells = vtk.vtkCellArray()
        for t in faces:
            cells.InsertNextCell(3, [int(v) for v in t])
        poly.SetPoints(p)
        poly.SetPolys(cells)
        return poly
    reader = {"stl": vtk.vtkSTLReader, "obj": vtk.vtkOBJReader, "ply": vtk.vtkPLYReader, "vtp": vtk.vtkXMLPolyDataReader}[ext]()
    reader.SetFileName(path)
    reader.Update()
    poly = reader.GetOutput()
    if ext == "stl":  # STL repeats each corner: weld exactly equal points (tolerance 0)
        clean = vtk.vtkCleanPolyData()
        clean.SetInputData(poly)
        clean.SetTolerance(0.0)
        clean.PointMergingOn()
        clean.Update()
        poly = clean.GetOutput()
    return poly


def faces_of(poly):
    conn = vtk_to_numpy(poly.GetPolys().GetConnectivityArray())
    return conn.reshape(-1, 3)


def edge_counts(poly):
    # One vtkFeatureEdges per kind (VTK 9.1 fails re-running one filter with other flags). On
    # millions of triangles VTK 9.1's filter fails to allocate its point locator: there the
    # edges are counted from the faces (numpy).
    if poly.GetNumberOfCells() > 1_000_000:
        faces = faces_of(poly)
        edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
        _, uses = np.unique(edges, axis=0, return_counts=True)
        return [int((uses == 1).sum()), int((uses > 2).sum())]
    counts = []
    for boundary in (True, False):
        fe = vtk.vtkFeatureEdges()
        fe.SetInputData(poly)
        fe.SetBoundaryEdges(boundary)
        fe.SetNonManifoldEdges(not boundary)
        fe.FeatureEdgesOff()
        fe.ManifoldEdgesOff()
        fe.Update()
        counts.append(fe.GetOutput().GetNumberOfLines())
    return counts


def regions(pts, faces):
    # Connected components over shared vertices; per component V − E + F and the signed volume.
    n = len(pts)
    graph = coo_matrix((np.ones(2 * len(faces)), (np.concatenate([faces[:, 0], faces[:, 0]]), np.concatenate([faces[:, 1], faces[:, 2]]))), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    comp_of_face = label[faces[:, 0]]
    out = []
    for r in np.unique(comp_of_face):
        f = faces[comp_of_face == r]
        v = len(np.unique(f))
        e = np.unique(np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1), axis=0)
        a, b, c = pts[f[:, 0]], pts[f[:, 1]], pts[f[:, 2]]
        vol = float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)
        chi = v - len(e) + len(f)
        lo, hi = pts[np.unique(f)].min(axis=0), pts[np.unique(f)].max(axis=0)
        out.append({"vertices": int(v), "faces": int(len(f)), "euler": int(chi), "genus": (2 - chi) / 2, "signed_volume": vol,
                    "box": [lo.tolist(), hi.tolist()]})
    return out


def read_tree(nodes_csv, edges_csv):
    pos = {}
    with open(nodes_csv) as f:
        for r in csv.DictReader(f):
            pos[r["id"]] = np.array([float(r["pos_x"]), float(r["pos_y"]), float(r["pos_z"])])
    a, b, rad = [], [], []
    with open(edges_csv) as f:
        for r in csv.DictReader(f):
            a.append(pos[r["node1id"]])
            b.append(pos[r["node2id"]])
            rad.append(float(r["radius"]))
    return np.array(a), np.array(b), np.array(rad)


def capsule_union_volume(nodes_csv, edges_csv, per_capsule=4000, seed=5):
    a, b, rad = read_tree(nodes_csv, edges_csv)
    d = b - a
    length = np.linalg.norm(d, axis=1)
    vol = np.pi * rad**2 * length + 4 / 3 * np.pi * rad**3
    mid = (a + b) / 2
    reach = length / 2 + rad
    tree = cKDTree(mid)
    rng = np.random.default_rng(seed)
    estimate = 0.0
    for s in range(len(a)):
        # Uniform points in capsule s: rejection from its bounding box.
        lo = np.minimum(a[s], b[s]) - rad[s]
        hi = np.maximum(a[s], b[s]) + rad[s]
        pts = np.empty((0, 3))
        while len(pts) < per_capsule:
            p = rng.uniform(lo, hi, size=(4 * per_capsule, 3))
            pts = np.vstack([pts, p[inside(p, a[s], d[s], rad[s])]])
        pts = pts[:per_capsule]
        idx = np.array(tree.query_ball_point(mid[s], reach[s] + reach.max()))  # capsules that may overlap it
        ap = pts[:, None, :] - a[idx][None, :, :]
        t = np.clip(np.einsum("pkj,kj->pk", ap, d[idx]) / np.einsum("kj,kj->k", d[idx], d[idx]), 0, 1)
        q = a[idx][None, :, :] + t[:, :, None] * d[idx][None, :, :]
        count = (np.linalg.norm(pts[:, None, :] - q, axis=2) <= rad[idx][None, :]).sum(axis=1)
        estimate += vol[s] * np.mean(1 / count)
    return estimate


def inside(p, a, d, r):
    t = np.clip(((p - a) @ d) / (d @ d), 0, 1)
    q = a + t[:, None] * d
    return np.linalg.norm(p - q, axis=1) <= r


def self_intersections(mesh_dir, exts):
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for ext in exts:
            poly = read(f"{mesh_dir}/surface.{ext}")
            pts = vtk_to_numpy(poly.GetPoints().GetData()).astype(float)
            faces = faces_of(poly)
            path = os.path.join(tmp, f"{ext}.off")
            with open(path, "w") as f:  # repr: every double exactly
                f.write(f"OFF\n{len(pts)} {len(faces)} 0\n")
                f.writelines(f"{x!r} {y!r} {z!r}\n" for x, y, z in pts)
                f.writelines(f"3 {a} {b} {c}\n" for a, b, c in faces)
            log = subprocess.run(["tetgen", "-d", path], capture_output=True, text=True).stdout
            found = re.search(r"Found (\d+) pairs of faces are intersecting", log)
            if found:
                out[ext] = int(found.group(1))
            elif "No faces are intersecting" in log:
                out[ext] = 0
            else:
                raise SystemExit(f"tetgen -d gave no verdict on {ext}:\n{log[-2000:]}")
    return out


def ends(mesh_dir):
    poly = read(f"{mesh_dir}/surface.vtp")
    pts = vtk_to_numpy(poly.GetPoints().GetData()).astype(float)
    faces = faces_of(poly)
    cd = poly.GetCellData()
    ids = vtk_to_numpy(cd.GetArray("ModelFaceID"))
    assert (ids == vtk_to_numpy(cd.GetArray("CellEntityIds"))).all()
    rows = list(csv.DictReader(open(f"{mesh_dir}/surface_faces.csv")))
    planes = []
    out = {"faces": len(rows), "wall_triangles": int((ids == 1).sum()), "caps": 0, "max_cap_plane_distance": 0.0,
           "min_cap_area_ratio": 9.0, "max_cap_area_ratio": 0.0, "min_cap_normal_cosine": 1.0, "states": {}}
    for row in rows[1:]:
        out["states"][row["state"]] = out["states"].get(row["state"], 0) + 1
        c = np.array([float(row[f"centre_{a}"]) for a in "xyz"])
        n = np.array([float(row[f"normal_{a}"]) for a in "xyz"])
        r = float(row["radius"])
        planes.append((c, n, r))
        mine = faces[ids == int(row["face_id"])]
        if row["state"] != "capped":
            assert len(mine) == 0, row
            continue
        out["caps"] += 1
        p = pts[mine]
        out["max_cap_plane_distance"] = max(out["max_cap_plane_distance"], float(np.abs((p - c) @ n).max() / r))
        cr = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        area = 0.5 * np.linalg.norm(cr, axis=1)
        ratio = float(area.sum() / (np.pi * r * r))
        out["min_cap_area_ratio"] = min(out["min_cap_area_ratio"], ratio)
        out["max_cap_area_ratio"] = max(out["max_cap_area_ratio"], ratio)
        out["min_cap_normal_cosine"] = min(out["min_cap_normal_cosine"], float(((cr / (2 * area[:, None])) @ n).min()))
    # Boundary loops: connected sets of boundary edges, each within a plane.
    fe = vtk.vtkFeatureEdges()
    fe.SetInputData(poly)
    fe.BoundaryEdgesOn()
    fe.NonManifoldEdgesOff()
    fe.FeatureEdgesOff()
    fe.ManifoldEdgesOff()
    fe.Update()
    edges = fe.GetOutput()
    loops, worst = 0, 0.0
    if edges.GetNumberOfCells() > 0:
        conn = vtk.vtkPolyDataConnectivityFilter()
        conn.SetInputData(edges)
        conn.SetExtractionModeToAllRegions()
        conn.ColorRegionsOn()
        conn.Update()
        loops = conn.GetNumberOfExtractedRegions()
        lp = vtk_to_numpy(conn.GetOutput().GetPoints().GetData()).astype(float)
        region = vtk_to_numpy(conn.GetOutput().GetPointData().GetArray("RegionId"))
        for k in range(loops):
            q = lp[region == k]
            worst = max(worst, min(float(np.abs((q - c) @ n).max() / r) for c, n, r in planes))
    out["boundary_loops"] = int(loops)
    out["max_loop_plane_distance"] = worst
    return out


def lumen_distance(p, a, b, rad):
    # Signed distance of points p to the union of the capsules (a, b, rad), by brute force in blocks.
    d = b - a
    out = np.full(len(p), np.inf)
    for k in range(0, len(a), 64):
        aa, dd, rr = a[k:k + 64], d[k:k + 64], rad[k:k + 64]
        t = np.clip(np.einsum("pkj,kj->pk", p[:, None, :] - aa[None], dd) / np.einsum("kj,kj->k", dd, dd), 0, 1)
        q = aa[None] + t[:, :, None] * dd[None]
        out = np.minimum(out, (np.linalg.norm(p[:, None, :] - q, axis=2) - rr[None]).min(axis=1))
    return out


def wall(mesh_dir, nodes_csv, edges_csv, thickness, clip=None, per_capsule=3000, seed=7):
    a, b, rad = read_tree(nodes_csv, edges_csv)
    d = b - a
    # The ends' rows (a clip box's sides have rows of kind "box": the box itself cuts).
    rows = [r for r in list(csv.DictReader(open(f"{mesh_dir}/surface_faces.csv")))[1:] if r["kind"] != "box"]
    in_box = (lambda p: np.ones(len(p), bool)) if clip is None else \
        (lambda p: np.all((p >= np.array(clip[:3])) & (p <= np.array(clip[3:])), axis=1))
    # Each end's plane belongs to the vessel with an end node at its centre.
    cuts = [[] for _ in range(len(a))]
    for row in rows:
        c = np.array([float(row[f"centre_{x}"]) for x in "xyz"])
        n = np.array([float(row[f"normal_{x}"]) for x in "xyz"])
        ends_at = np.minimum(np.linalg.norm(a - c, axis=1), np.linalg.norm(b - c, axis=1))
        cuts[int(np.argmin(ends_at))].append((c, n))
    out_r = rad + thickness

    def in_cut_capsule(p, k):
        keep = inside(p, a[k], d[k], out_r[k]) & in_box(p)
        for c, n in cuts[k]:
            keep &= (p - c) @ n <= 0
        return keep

    mid = (a + b) / 2
    reach = np.linalg.norm(d, axis=1) / 2 + out_r
    kd = cKDTree(mid)
    rng = np.random.default_rng(seed)
    volume = 0.0
    for s in range(len(a)):
        lo = np.minimum(a[s], b[s]) - out_r[s]
        hi = np.maximum(a[s], b[s]) + out_r[s]
        box = float(np.prod(hi - lo))
        p = rng.uniform(lo, hi, size=(per_capsule * 4, 3))
        p = p[inside(p, a[s], d[s], out_r[s])]  # uniform in the thickened capsule
        capsule = np.pi * out_r[s] ** 2 * np.linalg.norm(d[s]) + 4 / 3 * np.pi * out_r[s] ** 3
        near = kd.query_ball_point(mid[s], reach[s] + reach.max())
        count = np.zeros(len(p))
        for k in near:
            count += in_cut_capsule(p, k)
        mine = in_cut_capsule(p, s)
        wall_pt = mine & (lumen_distance(p, a[near], b[near], rad[near]) > 0)
        volume += capsule * float(np.sum(wall_pt / np.maximum(count, 1))) / len(p)
    poly = read(f"{mesh_dir}/surface.vtp")
    pts = vtk_to_numpy(poly.GetPoints().GetData()).astype(float)
    faces = faces_of(poly)
    face_id = vtk_to_numpy(poly.GetCellData().GetArray("ModelFaceID"))
    dist = lumen_distance(pts, a, b, rad)
    lumen_side = np.abs(dist) < thickness / 2
    keep = (face_id == 1) & lumen_side[faces].all(axis=1)
    lp = vtk.vtkPolyData()
    lp.SetPoints(poly.GetPoints())
    cells = vtk.vtkCellArray()
    for t in faces[keep]:
        cells.InsertNextCell(3, [int(v) for v in t])
    lp.SetPolys(cells)
    implicit = vtk.vtkImplicitPolyDataDistance()
    implicit.SetInput(lp)
    # Outer-side vertices away from the cut ends (where the wall is cut across, not around).
    outer = np.where(dist > thickness / 2)[0]
    far = np.ones(len(outer), bool)
    for row in rows:
        c = np.array([float(row[f"centre_{x}"]) for x in "xyz"])
        far &= np.linalg.norm(pts[outer] - c, axis=1) > 2 * (float(row["radius"]) + thickness)
    if clip is not None:  # the box cuts the wall across, not around
        lo, hi = np.array(clip[:3]), np.array(clip[3:])
        far &= np.minimum(pts[outer] - lo, hi - pts[outer]).min(axis=1) > 2 * thickness
    outer = outer[far]
    thick = np.array([abs(implicit.EvaluateFunction(*pts[i])) for i in outer])
    dev = np.abs(thick - thickness) / thickness
    mass = vtk.vtkMassProperties()
    mass.SetInputData(poly)
    mass.Update()
    openings = {}
    if clip is not None:
        # The lumen's openings: the open end rings, and the holes of the box's sections (a
        # patch of c components and Euler characteristic chi has c - chi holes).
        all_rows = list(csv.DictReader(open(f"{mesh_dir}/surface_faces.csv")))
        sec = faces[np.isin(face_id, [int(r["face_id"]) for r in all_rows if r["kind"] == "box"])]
        edges = {tuple(sorted((int(t[i]), int(t[(i + 1) % 3])))) for t in sec for i in range(3)}
        verts = np.unique(sec)
        parent = {int(v): int(v) for v in verts}

        def root(x):
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x
        for u, v in edges:
            parent[root(u)] = root(v)
        components = len({root(int(v)) for v in verts})
        holes = components - (len(verts) - len(edges) + len(sec))
        rings = sum(1 for r in rows if r["state"] == "open")
        openings = {"open_rings": rings, "section_holes": holes, "lumen_openings": rings + holes}
    return {**openings, "wall_volume_monte_carlo": volume, "mesh_volume": mass.GetVolume(), "outer_vertices": int(len(outer)),
            "thickness_deviation_p50": float(np.percentile(dev, 50)), "thickness_deviation_p95": float(np.percentile(dev, 95)),
            "thickness_min": float(thick.min()), "thickness_max": float(thick.max())}


def main():
    if sys.argv[1] == "--wall":
        box = [float(v) for v in sys.argv[6].split(",")] if len(sys.argv) > 6 else None
        print(json.dumps(wall(sys.argv[2], sys.argv[3], sys.argv[4], float(sys.argv[5]), box)))
        return
    if sys.argv[1] == "--ends":
        print(json.dumps(ends(sys.argv[2])))
        return
    if sys.argv[1] == "--self-intersections":
        print(json.dumps(self_intersections(sys.argv[2], sys.argv[3:])))
        return
    mesh_dir, nodes_csv, edges_csv = sys.argv[1:4]
    result = {"formats": {}}
    for ext in ["stl", "obj", "ply", "off", "vtp", "3mf"]:
        poly = read(f"{mesh_dir}/surface.{ext}")
        pts = vtk_to_numpy(poly.GetPoints().GetData()).astype(float)
        faces = faces_of(poly)
        boundary, nonmanifold = edge_counts(poly)
        sorted_faces = np.sort(faces, axis=1)
        duplicate = len(faces) - len(np.unique(sorted_faces, axis=0))
        area2 = np.linalg.norm(np.cross(pts[faces[:, 1]] - pts[faces[:, 0]], pts[faces[:, 2]] - pts[faces[:, 0]]), axis=1)
        mass = vtk.vtkMassProperties()
        mass.SetInputData(poly)
        mass.Update()
        result["formats"][ext] = {
            "points": int(len(pts)),
            "triangles": int(len(faces)),
            "boundary_edges": int(boundary),
            "nonmanifold_edges": int(nonmanifold),
            "duplicate_faces": int(duplicate),
            "degenerate_faces": int((area2 == 0).sum()),
            "volume": mass.GetVolume(),
            "regions": regions(pts, faces),
        }
    result["union_volume_monte_carlo"] = capsule_union_volume(nodes_csv, edges_csv)
    print(json.dumps(result))


if __name__ == "__main__":
    main()
