// 3MF (3D Manufacturing Format, core specification 1.3): the slicers' and printers' format. A ZIP
// package (libzip) of the content types, the package relationships and 3D/3dmodel.model, an XML
// model in millimetres with one mesh object per tree (its own vertex list, triangles
// counter-clockwise seen from outside, as the specification asks) and a build item for each.
#include <zip.h>

#include <ctime>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/format.hpp"
#include "io/mesh_writers.hpp"

namespace angiosynth {
namespace {

const char* kContentTypes =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    "<Types xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\">"
    "<Default Extension=\"rels\" ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/>"
    "<Default Extension=\"model\" ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/></Types>\n";
const char* kRelationships =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    "<Relationships xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\">"
    "<Relationship Target=\"/3D/3dmodel.model\" Id=\"rel0\" Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/>"
    "</Relationships>\n";

std::string modelXml(const SurfaceMesh& m) {
  std::string x;
  x.reserve(m.vertices.size() * 64 + m.triangles.size() * 40 + 1024);
  x += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
       "<model unit=\"millimeter\" xml:lang=\"en-US\" xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n"
       "<metadata name=\"Application\">angiosynth</metadata>\n<resources>\n";
  std::int32_t trees = 0;
  for (auto t : m.triangle_tree) trees = std::max(trees, t + 1);
  std::vector<std::int32_t> local(m.vertices.size(), -1), order;
  std::vector<std::int32_t> objects;
  for (std::int32_t tree = 0; tree < trees; ++tree) {
    order.clear();
    for (std::size_t k = 0; k < m.triangles.size(); ++k)
      if (m.triangle_tree[k] == tree)
        for (auto v : m.triangles[k])
          if (local[std::size_t(v)] < 0) local[std::size_t(v)] = std::int32_t(order.size()), order.push_back(v);
    if (order.empty()) continue;
    objects.push_back(tree + 1);
    x += "<object id=\"" + std::to_string(tree + 1) + "\" type=\"model\" name=\"tree " + std::to_string(tree) + "\">\n<mesh>\n<vertices>\n";
    for (auto v : order) {
      const Vec3& p = m.vertices[std::size_t(v)];
      x += "<vertex x=\"" + exactNumber(p.x) + "\" y=\"" + exactNumber(p.y) + "\" z=\"" + exactNumber(p.z) + "\"/>\n";
    }
    x += "</vertices>\n<triangles>\n";
    for (std::size_t k = 0; k < m.triangles.size(); ++k)
      if (m.triangle_tree[k] == tree) {
        const auto& t = m.triangles[k];
        x += "<triangle v1=\"" + std::to_string(local[std::size_t(t[0])]) + "\" v2=\"" + std::to_string(local[std::size_t(t[1])]) + "\" v3=\"" +
             std::to_string(local[std::size_t(t[2])]) + "\"/>\n";
      }
    x += "</triangles>\n</mesh>\n</object>\n";
    for (auto v : order) local[std::size_t(v)] = -1;
  }
  x += "</resources>\n<build>\n";
  for (auto id : objects) x += "<item objectid=\"" + std::to_string(id) + "\"/>\n";
  x += "</build>\n</model>\n";
  return x;
}

void check(bool ok, const char* what, zip_t* za = nullptr) {
  if (!ok) throw std::runtime_error(std::string("3MF package: ") + what + (za ? std::string(": ") + zip_strerror(za) : std::string()));
}

}  // namespace

void writeThreeMf(std::ostream& out, const SurfaceMesh& m) {
  const std::string model = modelXml(m);
  zip_error_t error;
  zip_error_init(&error);
  zip_source_t* buffer = zip_source_buffer_create(nullptr, 0, 0, &error);
  check(buffer != nullptr, "cannot create the buffer");
  zip_t* za = zip_open_from_source(buffer, ZIP_TRUNCATE, &error);
  if (!za) zip_source_free(buffer);
  check(za != nullptr, "cannot open the buffer");
  zip_source_keep(buffer);
  // Entries dated 1 January 1980 (ZIP's first day), so the same mesh gives the same bytes.
  std::tm day{};
  day.tm_year = 80, day.tm_mday = 1, day.tm_hour = 12;
  const std::time_t fixed = std::mktime(&day);
  for (const auto& [name, text] : {std::pair<const char*, std::string_view>{"[Content_Types].xml", kContentTypes},
                                   {"_rels/.rels", kRelationships},
                                   {"3D/3dmodel.model", model}}) {
    zip_source_t* s = zip_source_buffer(za, text.data(), text.size(), 0);
    check(s != nullptr, "cannot add a file", za);
    const zip_int64_t index = zip_file_add(za, name, s, ZIP_FL_ENC_UTF_8);
    if (index < 0) zip_source_free(s);
    check(index >= 0, "cannot add a file", za);
    check(zip_set_file_compression(za, zip_uint64_t(index), ZIP_CM_DEFLATE, 6) == 0, "cannot set the compression", za);
    check(zip_file_set_mtime(za, zip_uint64_t(index), fixed, 0) == 0, "cannot set the date", za);
  }
  if (zip_close(za) != 0) {
    const std::string why = zip_strerror(za);
    zip_discard(za);
    zip_source_free(buffer);
    throw std::runtime_error("3MF package: " + why);
  }
  zip_stat_t st;
  zip_stat_init(&st);
  const bool ok = zip_source_open(buffer) == 0 && zip_source_stat(buffer, &st) == 0;
  std::vector<char> bytes(ok ? st.size : 0);
  const bool read = ok && zip_source_read(buffer, bytes.data(), bytes.size()) == zip_int64_t(bytes.size());
  if (ok) zip_source_close(buffer);
  zip_source_free(buffer);
  check(read, "cannot read the package back");
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

}  // namespace angiosynth
