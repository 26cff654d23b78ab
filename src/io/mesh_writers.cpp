#include "io/mesh_writers.hpp"

#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "core/format.hpp"
#include "io/format_lists.hpp"

namespace angiosynth {
namespace {

// Little-endian bytes of a value (x86-64 and every platform Debian builds this for store so).
template <class T>
void put(std::ostream& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.write(b, sizeof(T));
}

Vec3 normalOf(const SurfaceMesh& m, const std::array<std::int32_t, 3>& t) {
  const Vec3 n = cross(m.vertices[t[1]] - m.vertices[t[0]], m.vertices[t[2]] - m.vertices[t[0]]);
  const double l = norm(n);
  return l > 0 ? n / l : n;
}

}  // namespace

void writeStl(std::ostream& out, const SurfaceMesh& m) {
  char header[80] = {};
  std::strncpy(header, "angiosynth vessel surface, mm", sizeof header - 1);
  out.write(header, sizeof header);
  put(out, std::uint32_t(m.triangles.size()));
  for (const auto& t : m.triangles) {
    const Vec3 n = normalOf(m, t);
    for (double c : {n.x, n.y, n.z}) put(out, float(c));
    for (auto v : t)
      for (double c : {m.vertices[v].x, m.vertices[v].y, m.vertices[v].z}) put(out, float(c));
    put(out, std::uint16_t(0));
  }
}

void writeObj(std::ostream& out, const SurfaceMesh& m) {
  out << "# angiosynth vessel surface; mm; faces counter-clockwise seen from outside\n";
  for (const auto& v : m.vertices) out << "v " << exactNumber(v.x) << ' ' << exactNumber(v.y) << ' ' << exactNumber(v.z) << '\n';
  // Groups: each tree's wall, then (ends cut) each cap: g tree<T> and g tree<T>_face<ModelFaceID>.
  std::int32_t tree = -1, face = 0;
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    const std::int32_t f = m.triangle_face.empty() ? 0 : m.triangle_face[k];
    if (m.triangle_tree[k] != tree || f != face) {
      out << "g tree" << (tree = m.triangle_tree[k]);
      if ((face = f) > 0) out << "_face" << f + 1;
      out << '\n';
    }
    const auto& t = m.triangles[k];
    out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  }
}

void writePly(std::ostream& out, const SurfaceMesh& m) {
  out << "ply\nformat binary_little_endian 1.0\ncomment angiosynth vessel surface, mm\n"
      << "element vertex " << m.vertices.size() << "\nproperty double x\nproperty double y\nproperty double z\n"
      << "element face " << m.triangles.size() << "\nproperty list uchar int vertex_indices\nproperty int tree\n"
      << (m.triangle_face.empty() ? "" : "property int face\n") << "end_header\n";
  for (const auto& v : m.vertices)
    for (double c : {v.x, v.y, v.z}) put(out, c);
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    put(out, std::uint8_t(3));
    for (auto v : m.triangles[k]) put(out, std::int32_t(v));
    put(out, std::int32_t(m.triangle_tree[k]));
    if (!m.triangle_face.empty()) put(out, std::int32_t(m.triangle_face[k] + 1));
  }
}

void writeOff(std::ostream& out, const SurfaceMesh& m) {
  out << "OFF\n" << m.vertices.size() << ' ' << m.triangles.size() << " 0\n";
  for (const auto& v : m.vertices) out << exactNumber(v.x) << ' ' << exactNumber(v.y) << ' ' << exactNumber(v.z) << '\n';
  for (const auto& t : m.triangles) out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
}

void writeMeshVtp(std::ostream& out, const SurfaceMesh& m) {
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\">\n<PolyData>\n"
      << "<Piece NumberOfPoints=\"" << m.vertices.size() << "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\""
      << m.triangles.size() << "\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& v : m.vertices) out << exactNumber(v.x) << ' ' << exactNumber(v.y) << ' ' << exactNumber(v.z) << '\n';
  out << "</DataArray>\n</Points>\n<CellData Scalars=\"Tree\">\n<DataArray type=\"Int32\" Name=\"Tree\" format=\"ascii\">\n";
  for (auto tree : m.triangle_tree) out << tree << '\n';
  // Face labels as VMTK (CellEntityIds) and SimVascular (ModelFaceID) read them: 1 the wall, 2 … the caps.
  for (const char* name : {"CellEntityIds", "ModelFaceID"}) {
    if (m.triangle_face.empty()) break;
    out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"" << name << "\" format=\"ascii\">\n";
    for (auto f : m.triangle_face) out << f + 1 << '\n';
  }
  out << "</DataArray>\n</CellData>\n<Polys>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& t : m.triangles) out << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t k = 1; k <= m.triangles.size(); ++k) out << 3 * k << '\n';
  out << "</DataArray>\n</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
}

namespace {

constexpr MeshFormat kMeshFormats[] = {
    {"stl", "binary STL", &writeStl}, {"obj", "Wavefront OBJ", &writeObj},    {"ply", "binary PLY", &writePly},
    {"off", "OFF", &writeOff},        {"vtp", "VTK PolyData", &writeMeshVtp}, {"3mf", "3MF, one object per tree", &writeThreeMf},
};

}  // namespace

std::span<const MeshFormat> meshFormats() { return kMeshFormats; }

std::vector<std::string> meshFormatNames() { return formatNames(meshFormats()); }
std::string meshFormatSummary() { return formatSummary(meshFormats()); }

MeshWriter meshWriter(const std::string& format) {
  if (const MeshFormat* f = findFormat(meshFormats(), format)) return f->write;
  std::string allowed;
  for (const auto& name : meshFormatNames()) allowed += (allowed.empty() ? "" : ", ") + name;
  throw std::invalid_argument("mesh format '" + format + "'; allowed: " + allowed);
}

}  // namespace angiosynth
