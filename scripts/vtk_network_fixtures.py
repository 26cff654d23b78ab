#!/usr/bin/python3
"""Writes tests/data/network/*.vtp from tree_ascii.vtp (angiosynth's own ascii VTP) with VTK's
own writer (python3-vtk9), so the network reader is tested on files VTK wrote, in each of its
encodings, and in VItA's layout (every vessel its own two points, VItA's cell arrays, no
point radius). Run from the repository root: /usr/bin/python3 scripts/vtk_network_fixtures.py"""
import vtk

DIR = "tests/data/network/"
reader = vtk.vtkXMLPolyDataReader()
reader.SetFileName(DIR + "tree_ascii.vtp")
reader.Update()
tree = reader.GetOutput()


def write(poly, name, mode, compress, header64):
    w = vtk.vtkXMLPolyDataWriter()
    w.SetFileName(DIR + name)
    w.SetInputData(poly)
    {"binary": w.SetDataModeToBinary, "appended": w.SetDataModeToAppended}[mode]()
    if mode == "appended":
        w.SetEncodeAppendedData(name.endswith("_base64.vtp"))
    if not compress:
        w.SetCompressorTypeToNone()
    else:
        w.SetCompressorTypeToZLib()
        w.SetBlockSize(512)  # several blocks per array
    if header64:
        w.SetHeaderTypeToUInt64()
    assert w.Write() == 1


write(tree, "tree_binary_zlib.vtp", "binary", True, False)
write(tree, "tree_binary_plain.vtp", "binary", False, False)
write(tree, "tree_appended_raw_zlib64.vtp", "appended", True, True)
write(tree, "tree_appended_base64.vtp", "appended", False, True)

# VItA's layout: two points per vessel, cell arrays radius, vesselFunction, branchingType, stage,
# ID_Vessel with VItA's codes, lines as three-point polylines (a midpoint: a chain of two segments).
role_to_vita = {1: 0, 2: 2, 3: 1}
branching_to_vita = {1: 2, 2: 1, 3: 3, 4: 0}
cells = tree.GetCellData()
points = vtk.vtkPoints()
points.SetDataTypeToDouble()
lines = vtk.vtkCellArray()
arrays = {n: vtk.vtkDoubleArray() for n in ("radius", "vesselFunction", "branchingType", "stage", "ID_Vessel")}
for n, a in arrays.items():
    a.SetName(n)
ids = vtk.vtkIdList()
for c in range(tree.GetNumberOfCells()):
    tree.GetCellPoints(c, ids)
    a, b = tree.GetPoint(ids.GetId(0)), tree.GetPoint(ids.GetId(1))
    mid = [(a[k] + b[k]) / 2 for k in range(3)]
    line = vtk.vtkPolyLine()
    for p in (a, mid, b):
        line.GetPointIds().InsertNextId(points.InsertNextPoint(p))
    lines.InsertNextCell(line)
    arrays["radius"].InsertNextValue(cells.GetArray("Radius").GetValue(c))
    arrays["vesselFunction"].InsertNextValue(role_to_vita[int(cells.GetArray("Role").GetValue(c))])
    arrays["branchingType"].InsertNextValue(branching_to_vita[int(cells.GetArray("Branching").GetValue(c))])
    arrays["stage"].InsertNextValue(cells.GetArray("Stage").GetValue(c))
    arrays["ID_Vessel"].InsertNextValue(100 + c)
vita = vtk.vtkPolyData()
vita.SetPoints(points)
vita.SetLines(lines)
for a in arrays.values():
    vita.GetCellData().AddArray(a)
write(vita, "tree_vita_polylines.vtp", "appended", True, False)
