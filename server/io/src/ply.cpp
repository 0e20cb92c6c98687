// Stanford PLY (mesh_io.h): header, ASCII and binary bodies. Every count in
// the header is checked against the bytes the body has before anything is
// allocated for it (plyMinimumBytes).
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "haarcast/io/mesh_io.h"
#include "mesh_finish.h"

namespace haarcast::io {
namespace {

using detail::finishMesh;

[[noreturn]] void fail(const std::string& where, const std::string& what) { detail::meshFail(where, what); }

enum class PlyType : std::uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

// Both spellings the PLY documents use (Turk's original names and the
// sized names of later writers such as the Stanford repository's bunny).
std::optional<PlyType> plyTypeOf(std::string_view name) {
  if (name == "char" || name == "int8") return PlyType::Int8;
  if (name == "uchar" || name == "uint8") return PlyType::UInt8;
  if (name == "short" || name == "int16") return PlyType::Int16;
  if (name == "ushort" || name == "uint16") return PlyType::UInt16;
  if (name == "int" || name == "int32") return PlyType::Int32;
  if (name == "uint" || name == "uint32") return PlyType::UInt32;
  if (name == "float" || name == "float32") return PlyType::Float32;
  if (name == "double" || name == "float64") return PlyType::Float64;
  return std::nullopt;
}

std::size_t plySize(PlyType t) {
  switch (t) {
    case PlyType::Int8:
    case PlyType::UInt8:
      return 1;
    case PlyType::Int16:
    case PlyType::UInt16:
      return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32:
      return 4;
    case PlyType::Float64:
      return 8;
  }
  return 0;
}

bool isIntegerType(PlyType t) { return t != PlyType::Float32 && t != PlyType::Float64; }

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;  // the item type for a list
  bool isList = false;
  PlyType countType = PlyType::UInt8;
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat : std::uint8_t { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct PlyHeader {
  PlyFormat format = PlyFormat::Ascii;
  std::vector<PlyElement> elements;
  std::size_t dataOffset = 0;  // first byte after the end_header line
};

std::vector<std::string_view> splitWords(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// The header is ASCII lines ending in LF (some writers use CRLF) up to
// `end_header`; the body starts right after that line's terminator.
PlyHeader parsePlyHeader(std::string_view bytes, const std::string& where) {
  PlyHeader header;
  std::size_t pos = 0;
  bool sawFormat = false;
  int lineNumber = 0;
  while (true) {
    if (pos >= bytes.size()) fail(where, "PLY header has no end_header line (truncated?)");
    const std::size_t eol = bytes.find('\n', pos);
    if (eol == std::string_view::npos) fail(where, "PLY header has no end_header line (truncated?)");
    std::string_view line = bytes.substr(pos, eol - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = eol + 1;
    ++lineNumber;
    const std::string at = "PLY header line " + std::to_string(lineNumber);

    if (lineNumber == 1) {
      if (line != "ply") fail(where, "unknown format: the file does not start with the PLY magic line \"ply\"");
      continue;
    }
    const std::vector<std::string_view> w = splitWords(line);
    if (w.empty()) continue;
    const std::string_view keyword = w[0];
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") {
      header.dataOffset = pos;
      break;
    }
    if (keyword == "format") {
      if (w.size() != 3 || w[2] != "1.0") fail(where, at + ": unsupported format line \"" + std::string(line) + "\"");
      if (w[1] == "ascii") {
        header.format = PlyFormat::Ascii;
      } else if (w[1] == "binary_little_endian") {
        header.format = PlyFormat::BinaryLittleEndian;
      } else if (w[1] == "binary_big_endian") {
        header.format = PlyFormat::BinaryBigEndian;
      } else {
        fail(where, at + ": unknown PLY format \"" + std::string(w[1]) + "\"");
      }
      sawFormat = true;
    } else if (keyword == "element") {
      if (w.size() != 3) fail(where, at + ": malformed element line \"" + std::string(line) + "\"");
      PlyElement element;
      element.name = std::string(w[1]);
      unsigned long long count = 0;
      const auto [end, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), count);
      if (ec != std::errc() || end != w[2].data() + w[2].size()) {
        fail(where, at + ": element count \"" + std::string(w[2]) + "\" is not a non-negative integer");
      }
      if (count > kMaxMeshElements) {
        fail(where, at + ": element " + element.name + " count " + std::to_string(count) + " is absurd (over " +
                        std::to_string(kMaxMeshElements) + ")");
      }
      element.count = static_cast<std::size_t>(count);
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) fail(where, at + ": property before any element");
      PlyProperty property;
      if (w.size() == 5 && w[1] == "list") {
        const auto countType = plyTypeOf(w[2]);
        const auto itemType = plyTypeOf(w[3]);
        if (!countType || !itemType) fail(where, at + ": unknown list type in \"" + std::string(line) + "\"");
        if (!isIntegerType(*countType)) fail(where, at + ": list count type must be an integer type");
        property.isList = true;
        property.countType = *countType;
        property.type = *itemType;
        property.name = std::string(w[4]);
      } else if (w.size() == 3) {
        const auto type = plyTypeOf(w[1]);
        if (!type) fail(where, at + ": unknown property type \"" + std::string(w[1]) + "\"");
        property.type = *type;
        property.name = std::string(w[2]);
      } else {
        fail(where, at + ": malformed property line \"" + std::string(line) + "\"");
      }
      header.elements.back().properties.push_back(std::move(property));
    } else {
      fail(where, at + ": unknown keyword \"" + std::string(keyword) + "\"");
    }
  }
  if (!sawFormat) fail(where, "PLY header has no format line");
  return header;
}

// Reads the body value by value, in either encoding; every read checks for
// the end of the data, so a truncated file is reported, never over-read.
class PlyBodyReader {
 public:
  PlyBodyReader(std::string_view body, PlyFormat format, const std::string& where)
      : body_(body), format_(format), where_(where) {}

  bool ascii() const { return format_ == PlyFormat::Ascii; }
  std::size_t remaining() const { return body_.size() - pos_; }

  double readReal(PlyType t, const char* what) {
    if (ascii()) {
      const std::string_view token = nextToken(what);
      double v = 0.0;
      const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
      if (ec != std::errc() || end != token.data() + token.size()) badToken(token, what);
      return v;
    }
    return binaryValue(t, what);
  }

  std::int64_t readInteger(PlyType t, const char* what) {
    if (ascii()) {
      const std::string_view token = nextToken(what);
      std::int64_t v = 0;
      const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
      if (ec != std::errc() || end != token.data() + token.size()) badToken(token, what);
      return v;
    }
    if (!isIntegerType(t)) {
      // A float-typed index list: accept exact integers only.
      const double v = binaryValue(t, what);
      if (!(v == std::floor(v)) || std::abs(v) > 9e15) {
        fail(where_, std::string("non-integer ") + what + " " + std::to_string(v));
      }
      return static_cast<std::int64_t>(v);
    }
    return static_cast<std::int64_t>(binaryValue(t, what));
  }

  void skip(const PlyProperty& p) {
    if (p.isList) {
      const std::int64_t n = readInteger(p.countType, "list count");
      if (n < 0) fail(where_, "negative list length " + std::to_string(n) + " in property " + p.name);
      for (std::int64_t k = 0; k < n; ++k) skipScalar(p.type);
    } else {
      skipScalar(p.type);
    }
  }

 private:
  void skipScalar(PlyType t) {
    if (ascii()) {
      nextToken("skipped property");
    } else {
      need(plySize(t), "skipped property");
      pos_ += plySize(t);
    }
  }

  void need(std::size_t n, const char* what) {
    if (remaining() < n) fail(where_, std::string("truncated: the data ends in the middle of a ") + what);
  }

  std::string_view nextToken(const char* what) {
    while (pos_ < body_.size() && std::isspace(static_cast<unsigned char>(body_[pos_]))) ++pos_;
    const std::size_t start = pos_;
    while (pos_ < body_.size() && !std::isspace(static_cast<unsigned char>(body_[pos_]))) ++pos_;
    if (pos_ == start) fail(where_, std::string("truncated: the data ends before a ") + what);
    return body_.substr(start, pos_ - start);
  }

  [[noreturn]] void badToken(std::string_view token, const char* what) {
    fail(where_, std::string("bad ") + what + " \"" + std::string(token.substr(0, 32)) + "\" in ASCII data");
  }

  double binaryValue(PlyType t, const char* what) {
    const std::size_t n = plySize(t);
    need(n, what);
    std::array<unsigned char, 8> raw{};
    std::memcpy(raw.data(), body_.data() + pos_, n);
    pos_ += n;
    const bool fileLittle = format_ == PlyFormat::BinaryLittleEndian;
    if (fileLittle != (std::endian::native == std::endian::little)) std::reverse(raw.begin(), raw.begin() + n);
    switch (t) {
      case PlyType::Int8: return static_cast<double>(std::bit_cast<std::int8_t>(raw[0]));
      case PlyType::UInt8: return static_cast<double>(raw[0]);
      case PlyType::Int16: return static_cast<double>(load<std::int16_t>(raw));
      case PlyType::UInt16: return static_cast<double>(load<std::uint16_t>(raw));
      case PlyType::Int32: return static_cast<double>(load<std::int32_t>(raw));
      case PlyType::UInt32: return static_cast<double>(load<std::uint32_t>(raw));
      case PlyType::Float32: return static_cast<double>(load<float>(raw));
      case PlyType::Float64: return load<double>(raw);
    }
    return 0.0;
  }

  template <typename T>
  static T load(const std::array<unsigned char, 8>& raw) {
    T v;
    std::memcpy(&v, raw.data(), sizeof(T));
    return v;
  }

  std::string_view body_;
  std::size_t pos_ = 0;
  PlyFormat format_;
  const std::string& where_;
};

int findProperty(const PlyElement& e, std::string_view name) {
  for (std::size_t i = 0; i < e.properties.size(); ++i) {
    if (e.properties[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

// The fewest body bytes one entry of an element can take. Binary: its
// scalars' sizes, a list counting as its count alone (it may be empty).
// ASCII: kPlyMinAsciiValueBytes a value, a list again counting as one value.
constexpr std::size_t kPlyMinAsciiValueBytes = 2;  // one digit and one separator
std::size_t plyMinimumEntryBytes(const PlyElement& element, PlyFormat format) {
  std::size_t bytes = 0;
  for (const PlyProperty& p : element.properties) {
    bytes += format == PlyFormat::Ascii ? kPlyMinAsciiValueBytes : plySize(p.isList ? p.countType : p.type);
  }
  return bytes;
}

// Every element count against the body before anything is allocated: the
// elements up to each one need at least Σ count × plyMinimumEntryBytes, less
// one byte in ASCII (the file's last value needs no separator after it). A
// 200-byte header declaring 50 million vertices is refused here, not after
// reserving 1.2 GB for them.
void checkCountsFitTheBody(const PlyHeader& header, std::size_t bodyBytes, const std::string& where) {
  const bool ascii = header.format == PlyFormat::Ascii;
  // Counts are at most kMaxMeshElements and an entry's minimum is bounded by
  // the header's length: a double holds the sum without overflow, exactly up
  // to 2^53 bytes, far past any file.
  double needed = 0.0;
  for (const PlyElement& element : header.elements) {
    needed += static_cast<double>(element.count) * static_cast<double>(plyMinimumEntryBytes(element, header.format));
    const double neededHere = ascii && needed > 0.0 ? needed - 1.0 : needed;
    if (neededHere > static_cast<double>(bodyBytes)) {
      fail(where, "truncated: element " + element.name + " declares " + std::to_string(element.count) +
                      " entries; with the elements before it that needs at least " +
                      std::to_string(static_cast<unsigned long long>(neededHere)) + " bytes of " +
                      (ascii ? "ASCII" : "binary") + " data, and the file has " + std::to_string(bodyBytes) +
                      " bytes after its header");
    }
  }
}

// A polygon with more corners than this is a corrupt count, not a face.
constexpr std::int64_t kMaxPolygonCorners = 1 << 16;

}  // namespace

Mesh detail::parsePlyAs(std::string_view bytes, const std::string& where, const std::string& name) {
  const PlyHeader header = parsePlyHeader(bytes, where);

  const PlyElement* vertexElement = nullptr;
  const PlyElement* faceElement = nullptr;
  for (const PlyElement& e : header.elements) {
    if (e.name == "vertex" && !vertexElement) vertexElement = &e;
    if (e.name == "face" && !faceElement) faceElement = &e;
  }
  if (!vertexElement) fail(where, "PLY file has no vertex element");
  if (!faceElement) fail(where, "PLY file has no face element (point clouds are not meshes)");

  const std::array<int, 3> xyz{findProperty(*vertexElement, "x"), findProperty(*vertexElement, "y"),
                               findProperty(*vertexElement, "z")};
  const std::array<int, 3> nxyz{findProperty(*vertexElement, "nx"), findProperty(*vertexElement, "ny"),
                                findProperty(*vertexElement, "nz")};
  for (const int i : xyz) {
    if (i < 0) fail(where, "PLY vertex element lacks one of x, y, z");
    if (vertexElement->properties[static_cast<std::size_t>(i)].isList) fail(where, "PLY vertex x, y, z are lists");
  }
  bool hasNormals = std::all_of(nxyz.begin(), nxyz.end(), [&](int i) {
    return i >= 0 && !vertexElement->properties[static_cast<std::size_t>(i)].isList;
  });
  int indexList = findProperty(*faceElement, "vertex_indices");
  if (indexList < 0) indexList = findProperty(*faceElement, "vertex_index");
  if (indexList < 0 || !faceElement->properties[static_cast<std::size_t>(indexList)].isList) {
    fail(where, "PLY face element has no list property vertex_indices (or vertex_index)");
  }

  // What each vertex property feeds: 0–2 position, 3–5 normal, −1 skipped.
  std::vector<int> role(vertexElement->properties.size(), -1);
  for (int k = 0; k < 3; ++k) {
    role[static_cast<std::size_t>(xyz[static_cast<std::size_t>(k)])] = k;
    if (hasNormals) role[static_cast<std::size_t>(nxyz[static_cast<std::size_t>(k)])] = 3 + k;
  }

  checkCountsFitTheBody(header, bytes.size() - header.dataOffset, where);
  PlyBodyReader reader(bytes.substr(header.dataOffset), header.format, where);
  Mesh mesh;
  mesh.name = name;
  const std::size_t vertexCount = vertexElement->count;

  for (const PlyElement& element : header.elements) {
    if (&element == vertexElement) {
      mesh.positions.resize(vertexCount);
      if (hasNormals) mesh.normals.resize(vertexCount);
      for (std::size_t v = 0; v < vertexCount; ++v) {
        std::array<double, 6> values{};
        for (std::size_t p = 0; p < element.properties.size(); ++p) {
          const PlyProperty& property = element.properties[p];
          if (role[p] < 0) {
            reader.skip(property);
          } else {
            values[static_cast<std::size_t>(role[p])] = reader.readReal(property.type, "vertex value");
          }
        }
        mesh.positions[v] = glm::vec3(glm::dvec3(values[0], values[1], values[2]));
        if (hasNormals) mesh.normals[v] = glm::vec3(glm::dvec3(values[3], values[4], values[5]));
      }
    } else if (&element == faceElement) {
      mesh.triangles.reserve(element.count);
      std::vector<std::uint32_t> polygon;
      for (std::size_t f = 0; f < element.count; ++f) {
        for (std::size_t p = 0; p < element.properties.size(); ++p) {
          const PlyProperty& property = element.properties[p];
          if (static_cast<int>(p) != indexList) {
            reader.skip(property);
            continue;
          }
          const std::int64_t corners = reader.readInteger(property.countType, "face corner count");
          if (corners < 3 || corners > kMaxPolygonCorners) {
            fail(where, "face " + std::to_string(f) + " has " + std::to_string(corners) + " corners");
          }
          polygon.clear();
          for (std::int64_t k = 0; k < corners; ++k) {
            const std::int64_t index = reader.readInteger(property.type, "face vertex index");
            if (index < 0 || static_cast<std::uint64_t>(index) >= vertexCount) {
              fail(where, "face " + std::to_string(f) + " vertex index " + std::to_string(index) +
                              " is out of range [0, " + std::to_string(vertexCount) + ")");
            }
            polygon.push_back(static_cast<std::uint32_t>(index));
          }
          // Fan triangulation: exact for the convex polygons scanners and
          // modellers write; PLY has no notion of holes.
          for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
            mesh.triangles.emplace_back(polygon[0], polygon[k], polygon[k + 1]);
          }
          if (mesh.triangles.size() > kMaxMeshElements) {
            fail(where, "more than " + std::to_string(kMaxMeshElements) + " triangles is absurd");
          }
        }
      }
    } else {
      for (std::size_t i = 0; i < element.count; ++i) {
        for (const PlyProperty& property : element.properties) reader.skip(property);
      }
    }
  }
  return finishMesh(std::move(mesh), where);
}


Mesh parsePly(std::string_view bytes, const std::string& name) { return detail::parsePlyAs(bytes, name, name); }

}  // namespace haarcast::io
