#pragma once
// Surface mesh files: binary STL, OBJ, binary PLY, OFF, VTK PolyData and 3MF. Vertices are shared
// (welded) in every format that has a vertex list; STL has none, and its single-precision
// corners still weld back exactly (the mesher keeps vertices far apart compared with float
// rounding). Positions in mm; OBJ, PLY, OFF and VTP keep every bit of them.
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mesh/vessel_surface.hpp"

namespace angiosynth {

void writeStl(std::ostream& out, const SurfaceMesh& m);
void writeObj(std::ostream& out, const SurfaceMesh& m);
void writePly(std::ostream& out, const SurfaceMesh& m);  // binary little endian; face properties `tree` and (ends cut) `face`
void writeOff(std::ostream& out, const SurfaceMesh& m);
void writeMeshVtp(std::ostream& out, const SurfaceMesh& m);  // cell arrays `Tree` and (ends cut) `CellEntityIds`, `ModelFaceID`
void writeThreeMf(std::ostream& out, const SurfaceMesh& m);  // 3MF, millimetres, one object per tree (mesh_3mf.cpp)

// The mesh formats, one entry each: the parameter reader, the command line, `angiosynth params`
// and the surface writer read this list. The name is also the file extension (surface.<name>).
using MeshWriter = void (*)(std::ostream&, const SurfaceMesh&);
struct MeshFormat {
  std::string_view name;
  std::string_view meaning;  // for help and the parameter reference
  MeshWriter write;
};
std::span<const MeshFormat> meshFormats();
// The writer of a format name; throws std::invalid_argument for another name.
MeshWriter meshWriter(const std::string& format);
std::vector<std::string> meshFormatNames();
// "stl (binary), obj, …": the list with meanings, for help and references.
std::string meshFormatSummary();

}  // namespace angiosynth
