// Initial networks from VTK PolyData files (.vtp): VItA's trees and angiosynth's centerlines.vtp,
// as VTK writes them: ascii, inline base64 or appended (raw or base64) arrays, zlib-compressed
// or not, UInt32 or UInt64 headers. Lines run proximal to distal; a polyline of k points is a
// chain of k - 1 segments (a tortuous vessel kept as it is). Points that coincide are one node.
#include <tinyxml2.h>
#include <zlib.h>

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.hpp"
#include "core/memory.hpp"
#include "io/network_rows.hpp"

namespace angiosynth::network_detail {
namespace {

int base64Value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

// A stream of bytes: raw, or base64 text whose blocks VTK encodes one after another.
class ByteStream {
 public:
  ByteStream(std::string_view data, bool base64, std::string file, int line) : data_(data), base64_(base64), file_(std::move(file)), line_(line) {}
  // The next n bytes; a base64 block of n bytes takes 4·⌈n/3⌉ characters.
  std::vector<unsigned char> take(std::size_t n) {
    std::vector<unsigned char> out;
    if (!base64_) {
      if (pos_ + n > data_.size()) fail("ends before its data");
      out.assign(data_.begin() + std::ptrdiff_t(pos_), data_.begin() + std::ptrdiff_t(pos_ + n));
      pos_ += n;
      return out;
    }
    const std::size_t chars = (n + 2) / 3 * 4;
    if (pos_ + chars > data_.size()) fail("ends before its data");
    out.reserve(chars / 4 * 3);
    for (std::size_t k = pos_; k < pos_ + chars; k += 4) {
      int v[4];
      for (int j = 0; j < 4; ++j) {
        v[j] = data_[k + j] == '=' ? 0 : base64Value(data_[k + j]);
        if (v[j] < 0) fail("is not base64");
      }
      const std::uint32_t w = std::uint32_t(v[0]) << 18 | std::uint32_t(v[1]) << 12 | std::uint32_t(v[2]) << 6 | std::uint32_t(v[3]);
      out.push_back(static_cast<unsigned char>(w >> 16));
      out.push_back(static_cast<unsigned char>(w >> 8));
      out.push_back(static_cast<unsigned char>(w));
    }
    out.resize(n);
    pos_ += chars;
    return out;
  }
  // Base64 only: whether the last block taken ended in padding (it was encoded on its own).
  bool padded() const { return base64_ && pos_ > 0 && data_[pos_ - 1] == '='; }
  void rewind(std::size_t pos) { pos_ = pos; }
  std::size_t position() const { return pos_; }
  [[noreturn]] void fail(const std::string& what) const { throw InputError(file_, line_, "the DataArray's binary data " + what); }

 private:
  std::string_view data_;
  bool base64_;
  std::string file_;
  int line_;
  std::size_t pos_ = 0;
};

std::uint64_t word(const std::vector<unsigned char>& b, std::size_t k, std::size_t size) {
  std::uint64_t v = 0;
  for (std::size_t j = 0; j < size; ++j) v |= std::uint64_t(b[k * size + j]) << (8 * j);  // little-endian
  return v;
}

struct Encoding {
  std::size_t header = 4;  // bytes per header word: UInt32 or UInt64
  bool zlib = false;
};

// The bytes of one binary array, header first (VTK's layout): uncompressed [size] data, or
// compressed [blocks, block size, last block size, compressed sizes...] blocks.
// `expected`: the bytes the Piece asks for; a header that declares others is refused before
// anything is allocated.
std::vector<unsigned char> binaryArray(ByteStream& in, const Encoding& enc, std::uint64_t expected) {
  const std::size_t h = enc.header;
  if (!enc.zlib) {
    const std::size_t start = in.position();
    const auto head = in.take(h);
    const auto size = word(head, 0, h);
    if (size != expected) in.fail("declares " + std::to_string(size) + " bytes; the Piece asks for " + std::to_string(expected));
    if (h % 3 != 0 && !in.padded()) {  // header and data encoded together
      in.rewind(start);
      auto all = in.take(h + size);
      return {all.begin() + std::ptrdiff_t(h), all.end()};
    }
    return in.take(size);
  }
  const auto first = in.take(3 * h);
  const auto blocks = word(first, 0, h), block = word(first, 1, h), last = word(first, 2, h);
  const std::uint64_t total = blocks == 0 ? 0 : (blocks - 1) * block + (last != 0 ? last : block);
  if (blocks > (1u << 24) || (blocks > 1 && block > expected) || total != expected)
    in.fail("declares " + std::to_string(blocks) + " blocks of " + std::to_string(block) + " bytes; the Piece asks for " + std::to_string(expected));
  // 3 words (12 or 24 bytes) end on a base64 group: the header's rest continues its stream.
  auto head = first;
  const auto rest = in.take(blocks * h);
  head.insert(head.end(), rest.begin(), rest.end());
  // The compressed blocks follow as one stream.
  std::uint64_t packed_size = 0;
  for (std::uint64_t b = 0; b < blocks; ++b) packed_size += word(head, 3 + b, h);
  // zlib expands at most about 1032-fold: a header beyond that is not the data that follows.
  if (packed_size > (std::uint64_t(1) << 40) || expected > 1100 * packed_size + 1024)
    in.fail("declares " + std::to_string(packed_size) + " compressed bytes for " + std::to_string(expected));
  const auto packed_all = in.take(packed_size);
  std::vector<unsigned char> out;
  std::size_t from = 0;
  for (std::uint64_t b = 0; b < blocks; ++b) {
    const auto size = word(head, 3 + b, h);
    const std::vector<unsigned char> packed(packed_all.begin() + std::ptrdiff_t(from), packed_all.begin() + std::ptrdiff_t(from + size));
    from += size;
    const uLongf expect = uLongf(b + 1 == blocks && last != 0 ? last : block);
    uLongf got = expect;
    const auto at = out.size();
    out.resize(at + expect);
    if (uncompress(out.data() + at, &got, packed.data(), uLong(packed.size())) != Z_OK || got != expect) in.fail("is not valid zlib data");
  }
  return out;
}

struct ArrayInfo {
  const tinyxml2::XMLElement* element = nullptr;
  std::string name, type;
  int components = 1;
};

std::size_t typeSize(const std::string& file, int line, const std::string& type) {
  static const std::map<std::string, std::size_t> sizes{{"Int8", 1},   {"UInt8", 1}, {"Int16", 2},  {"UInt16", 2},  {"Int32", 4},
                                                        {"UInt32", 4}, {"Int64", 8}, {"UInt64", 8}, {"Float32", 4}, {"Float64", 8}};
  const auto it = sizes.find(type);
  if (it == sizes.end()) throw InputError(file, line, "DataArray type '" + type + "'; allowed: Int8 to UInt64, Float32, Float64");
  return it->second;
}

double valueAt(const unsigned char* p, const std::string& type) {
  const auto get = [p](auto v) {
    std::memcpy(&v, p, sizeof v);
    return double(v);
  };
  if (type == "Float64") return get(double());
  if (type == "Float32") return get(float());
  if (type == "Int64") return get(std::int64_t());
  if (type == "UInt64") return get(std::uint64_t());
  if (type == "Int32") return get(std::int32_t());
  if (type == "UInt32") return get(std::uint32_t());
  if (type == "Int16") return get(std::int16_t());
  if (type == "UInt16") return get(std::uint16_t());
  if (type == "Int8") return get(std::int8_t());
  return get(std::uint8_t());
}

class VtpFile {
 public:
  explicit VtpFile(const std::string& file) : file_(file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, 0, "cannot read the network file");
    std::stringstream ss;
    ss << in.rdbuf();
    bytes_ = ss.str();
    // Appended raw data is not XML: parse what precedes it, closed.
    std::string xml = bytes_;
    if (const auto at = bytes_.find("<AppendedData"); at != std::string::npos) {
      const auto tag_end = bytes_.find('>', at);
      const auto underscore = tag_end == std::string::npos ? tag_end : bytes_.find('_', tag_end);
      if (underscore == std::string::npos) throw InputError(file, 0, "<AppendedData> without its '_' marker");
      const auto close = bytes_.rfind("</AppendedData>");
      appended_ = std::string_view(bytes_).substr(underscore + 1,
                                                  (close == std::string::npos || close < underscore ? bytes_.size() : close) - underscore - 1);
      const std::string tag = bytes_.substr(at, tag_end - at + 1);
      appended_base64_ = tag.find("encoding=\"base64\"") != std::string::npos;
      if (appended_base64_)
        while (!appended_.empty() && std::isspace(static_cast<unsigned char>(appended_.back()))) appended_.remove_suffix(1);
      xml = bytes_.substr(0, at) + "</VTKFile>\n";
    }
    if (doc_.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS)
      throw InputError(file, doc_.ErrorLineNum(), std::string("not readable as XML: ") + doc_.ErrorStr());
    const auto* root = doc_.FirstChildElement("VTKFile");
    if (!root || !root->Attribute("type") || std::string(root->Attribute("type")) != "PolyData")
      throw InputError(file, 1, "not a VTK PolyData file (<VTKFile type=\"PolyData\">)");
    if (const char* order = root->Attribute("byte_order"); order && std::string(order) != "LittleEndian")
      throw InputError(file, root->GetLineNum(), std::string("byte_order ") + order + "; allowed: LittleEndian");
    if (const char* h = root->Attribute("header_type")) {
      if (std::string(h) != "UInt32" && std::string(h) != "UInt64")
        throw InputError(file, root->GetLineNum(), std::string("header_type ") + h + "; allowed: UInt32, UInt64");
      enc_.header = std::string(h) == "UInt64" ? 8 : 4;
    }
    if (const char* c = root->Attribute("compressor")) {
      if (std::string(c) != "vtkZLibDataCompressor")
        throw InputError(file, root->GetLineNum(), std::string("compressor ") + c + "; allowed: vtkZLibDataCompressor (write with zlib or none)");
      enc_.zlib = true;
    }
    const auto* poly = root->FirstChildElement("PolyData");
    piece_ = poly ? poly->FirstChildElement("Piece") : nullptr;
    if (!piece_) throw InputError(file, root->GetLineNum(), "no <PolyData><Piece>");
    if (piece_->NextSiblingElement("Piece")) throw InputError(file, piece_->GetLineNum(), "more than one Piece; allowed: one");
  }

  const tinyxml2::XMLElement* piece() const { return piece_; }

  // The DataArray named `name` under `section` (Points: the first), or null.
  const tinyxml2::XMLElement* array(const char* section, const char* name) const {
    const auto* s = piece_->FirstChildElement(section);
    if (!s) return nullptr;
    for (auto* a = s->FirstChildElement("DataArray"); a; a = a->NextSiblingElement("DataArray"))
      if (!name || (a->Attribute("Name") && std::string(a->Attribute("Name")) == name)) return a;
    return nullptr;
  }

  // All values of an array, as doubles; `count` values expected.
  std::vector<double> values(const tinyxml2::XMLElement* a, std::size_t count) const {
    const int line = a->GetLineNum();
    const std::string type = a->Attribute("type") ? a->Attribute("type") : "";
    const std::size_t size = typeSize(file_, line, type);
    const std::string format = a->Attribute("format") ? a->Attribute("format") : "ascii";
    std::vector<double> out;
    if (format == "ascii") {
      std::istringstream ss(a->GetText() ? a->GetText() : "");
      for (std::string t; ss >> t;) {
        char* end = nullptr;
        const double v = std::strtod(t.c_str(), &end);
        if (*end || !std::isfinite(v)) throw InputError(file_, line, "value '" + t + "' is not a finite number");
        out.push_back(v);
      }
    } else {
      std::vector<unsigned char> raw;
      if (format == "binary") {
        std::string text;
        for (const char* c = a->GetText() ? a->GetText() : ""; *c; ++c)
          if (!std::isspace(static_cast<unsigned char>(*c))) text += *c;
        ByteStream in(text, true, file_, line);
        raw = binaryArray(in, enc_, std::uint64_t(count) * size);
      } else if (format == "appended") {
        const auto offset = a->Unsigned64Attribute("offset", ~std::uint64_t(0));
        if (offset > appended_.size()) throw InputError(file_, line, "appended offset is missing or past the data");
        ByteStream in(appended_.substr(offset), appended_base64_, file_, line);
        raw = binaryArray(in, enc_, std::uint64_t(count) * size);
      } else {
        throw InputError(file_, line, "format '" + format + "'; allowed: ascii, binary, appended");
      }
      if (raw.size() % size) throw InputError(file_, line, "binary data of " + std::to_string(raw.size()) + " bytes for " + type + " values");
      for (std::size_t k = 0; k < raw.size(); k += size) {
        out.push_back(valueAt(raw.data() + k, type));
        if (!std::isfinite(out.back())) throw InputError(file_, line, "a value is not finite");
      }
    }
    if (out.size() != count) throw InputError(file_, line, std::to_string(out.size()) + " values; the Piece asks for " + std::to_string(count));
    return out;
  }

 private:
  std::string file_, bytes_;
  tinyxml2::XMLDocument doc_;
  const tinyxml2::XMLElement* piece_ = nullptr;
  std::string_view appended_;
  bool appended_base64_ = false;
  Encoding enc_;
};

}  // namespace

ExistingNetwork readVtp(const std::string& file, double unit_mm, std::uint64_t memory_limit) {
  const VtpFile vtp(file);
  const auto* piece = vtp.piece();
  const auto points_n = piece->Unsigned64Attribute("NumberOfPoints", 0), lines_n = piece->Unsigned64Attribute("NumberOfLines", 0);
  if (lines_n == 0) throw InputError(file, piece->GetLineNum(), "no lines: a network is the Piece's Lines");
  if (points_n > 50'000'000 || lines_n > 50'000'000)
    throw InputError(file, piece->GetLineNum(), "more than 5e7 points or lines; allowed: up to 5e7 (a vascular network, not a mesh)");
  // Compressed arrays expand up to a thousandfold: the counts the Piece declares are checked
  // against the limit before any array is decoded (a point: its coordinates, its node; a line: a
  // vessel at least).
  const auto refuseBeyondLimit = [&](std::uint64_t need) {
    if (need > memory_limit)
      throw InputError(file, piece->GetLineNum(),
                       "the Piece declares " + std::to_string(points_n) + " points and " + std::to_string(lines_n) + " lines, which need about " +
                           formatBytes(need) + " to read, more than the limit of " + formatBytes(memory_limit) + "; raise --memory-limit");
  };
  refuseBeyondLimit(points_n * 256 + lines_n * (kNetworkBytesPerVessel + 64));
  const auto* pts = vtp.array("Points", nullptr);
  if (!pts) throw InputError(file, piece->GetLineNum(), "no <Points> array");
  const auto xyz = vtp.values(pts, 3 * points_n);
  const auto* conn = vtp.array("Lines", "connectivity");
  const auto* offs = vtp.array("Lines", "offsets");
  if (!conn || !offs) throw InputError(file, piece->GetLineNum(), "<Lines> needs the arrays connectivity and offsets");
  const auto offsets = vtp.values(offs, lines_n);
  const double ends = offsets.back();
  if (!(ends >= 2 && ends <= 2.0 * double(points_n) + 2 * double(lines_n) && ends == std::floor(ends)))
    throw InputError(file, offs->GetLineNum(),
                     "the last offset must be the connectivity's length: a whole number, at most one point per line and point");
  refuseBeyondLimit(points_n * 256 + lines_n * 64 + std::uint64_t(ends) * (kNetworkBytesPerVessel + 8));
  const auto connectivity = vtp.values(conn, std::size_t(ends));
  // Coincident points are one node (VItA writes each vessel's own two points).
  std::map<std::array<double, 3>, std::size_t> node_of;
  std::vector<Vec3> nodes;
  std::vector<std::size_t> node(points_n);
  for (std::size_t p = 0; p < points_n; ++p) {
    const std::array<double, 3> c{xyz[3 * p], xyz[3 * p + 1], xyz[3 * p + 2]};
    const auto [it, added] = node_of.emplace(c, nodes.size());
    if (added) nodes.emplace_back(c[0], c[1], c[2]);
    node[p] = it->second;
  }
  // Per line: radius (VItA's "radius" or ours "Radius"; else the point array "Radius" at the
  // distal point), stage, role and branching (ours by name, else VItA's codes).
  const auto cellArray = [&](std::initializer_list<const char*> names) -> std::pair<std::vector<double>, const char*> {
    for (const char* n : names)
      if (const auto* a = vtp.array("CellData", n)) return {vtp.values(a, lines_n), n};
    return {{}, nullptr};
  };
  const auto [radius, radius_name] = cellArray({"Radius", "radius"});
  std::vector<double> point_radius;
  if (!radius_name) {
    const auto* a = vtp.array("PointData", "NodeRadius");
    if (!a) a = vtp.array("PointData", "Radius");
    if (!a) a = vtp.array("PointData", "radius");
    if (!a) throw InputError(file, piece->GetLineNum(), "no radius: a cell or point array named Radius or radius is required");
    point_radius = vtp.values(a, points_n);
  }
  const auto [stage, stage_name] = cellArray({"Stage", "stage"});
  const auto [role, role_name] = cellArray({"Role", "vesselFunction"});
  const auto [branching, branching_name] = cellArray({"Branching", "branchingType"});
  const auto [vessel_id, id_name] = cellArray({"ID_Vessel"});
  const auto [radius_start, radius_start_name] = cellArray({"RadiusStart"});
  const auto [wall_start, wall_start_name] = cellArray({"WallStart"});
  const auto [wall, wall_name] = cellArray({"Wall"});
  const int line = conn->GetLineNum();
  const auto whole = [&](double v, const char* what, std::size_t c) {
    if (v != std::floor(v) || std::abs(v) > 1e15)
      throw InputError(file, line, std::string(what) + " of line " + std::to_string(c) + " is not an integer");
    return static_cast<long long>(v);
  };
  std::vector<PointSegment> segments;
  std::size_t begin = 0;
  for (std::size_t c = 0; c < lines_n; ++c) {
    const double end = offsets[c];
    if (!(end >= double(begin) + 2 && end <= double(connectivity.size())))
      throw InputError(file, offs->GetLineNum(), "line " + std::to_string(c) + ": offsets must grow by 2 or more (a line has two points or more)");
    PointSegment s;
    s.row.line = line;
    const std::string base = id_name ? std::to_string(whole(vessel_id[c], id_name, c)) : std::to_string(c);
    if (stage_name) {
      if (stage[c] != std::floor(stage[c]) || stage[c] < -1 || stage[c] > 30000)
        throw InputError(file, line, std::string(stage_name) + " of line " + std::to_string(c) + " must be an integer in [-1, 30000]");
      s.row.stage = std::int16_t(stage[c]);
    }
    if (role_name) {
      const auto r = whole(role[c], role_name, c);
      if (std::string(role_name) == "Role") {
        if (r < 1 || r > 3) throw InputError(file, line, "Role " + std::to_string(r) + "; allowed: 1 distribution, 2 transport, 3 perforator");
        s.row.role = std::uint8_t(r);
      } else {
        s.row.role = roleFromVita(file, line, r);
      }
    }
    if (branching_name) {
      const auto b = whole(branching[c], branching_name, c);
      if (std::string(branching_name) == "Branching") {
        if (b < 1 || b > 4) throw InputError(file, line, "Branching " + std::to_string(b) + "; allowed: 1 versatile, 2 fixed, 3 distal, 4 none");
        s.row.branching = std::uint8_t(b);
      } else {
        s.row.branching = branchingFromVita(file, line, b);
      }
    }
    const auto last = std::size_t(end);
    if (last - begin > 2 && (radius_start_name || wall_start_name))
      throw InputError(file, line,
                       "line " + std::to_string(c) + " has " + std::to_string(last - begin) +
                           " points and a RadiusStart or WallStart: a tapered vessel is a line of two points");
    for (std::size_t k = begin; k + 1 < last; ++k) {
      const double a = connectivity[k], b = connectivity[k + 1];
      if (!(a >= 0 && b >= 0 && a < double(points_n) && b < double(points_n)))
        throw InputError(file, line, "line " + std::to_string(c) + " refers to a point that is not defined");
      s.from = node[std::size_t(a)];
      s.to = node[std::size_t(b)];
      s.row.radius = radius_name ? radius[c] : point_radius[std::size_t(b)];
      if (radius_start_name) s.row.radius_start = radius_start[c];
      if (wall_start_name) s.row.wall_start = wall_start[c];
      if (wall_name) s.row.wall = wall[c];
      s.row.id = last - begin == 2 ? base : base + "." + std::to_string(k - begin);
      segments.push_back(s);
    }
    begin = last;
  }
  return assemble(file, rowsFromPoints(file, nodes, std::move(segments)), false, unit_mm);
}

}  // namespace angiosynth::network_detail
