// Stanford PLY: ascii, binary_little_endian and binary_big_endian.
// Reads x, y, z of the `vertex` element (any numeric type) and the `vertex_indices` (or
// `vertex_index`) list of the `face` element (any count and index integer types), and when
// asked for (mesh_attributes.h) the vertex colours red, green, blue; every other property
// and element is skipped by its declared size. Writes doubles and ints (and uchar colours).
//
// Hostile files: the header's element counts are never trusted for allocation (reserves
// are clamped by the bytes actually left), every binary read is bounds-checked, and every
// loop iteration consumes input or fails, so garbage cannot make the reader hang.
#include <cmath>
#include <string>
#include <vector>

#include "byte_reader.h"
#include "mesh_builder.h"
#include "mesh_codecs.h"
#include "number_text.h"
#include "spherekit/version.h"
#include "text_scan.h"

namespace spherekit::formats::detail {
namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool parse_type(std::string_view name, PlyType& type) {
  struct Entry {
    const char* name;
    PlyType type;
  };
  static constexpr Entry kTypes[] = {
      {"char", PlyType::Int8},     {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
      {"uint8", PlyType::UInt8},   {"short", PlyType::Int16},     {"int16", PlyType::Int16},
      {"ushort", PlyType::UInt16}, {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
      {"int32", PlyType::Int32},   {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32}, {"float32", PlyType::Float32}, {"double", PlyType::Float64},
      {"float64", PlyType::Float64}};
  for (const Entry& e : kTypes) {
    if (name == e.name) {
      type = e.type;
      return true;
    }
  }
  return false;
}

std::size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::Int8:
    case PlyType::UInt8: return 1;
    case PlyType::Int16:
    case PlyType::UInt16: return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 1;
}

bool is_integer(PlyType t) { return t != PlyType::Float32 && t != PlyType::Float64; }

struct PlyProperty {
  std::string name;
  bool is_list = false;
  PlyType type = PlyType::Float32;        // value type (list item type for lists)
  PlyType count_type = PlyType::UInt8;    // lists only
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { Ascii, BinaryLE, BinaryBE };

struct PlyHeader {
  PlyFormat format = PlyFormat::Ascii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;     // first byte after the end_header line
  std::uint64_t body_line = 1;     // line number of that byte (ascii messages)
};

Result<PlyHeader> parse_header(const std::string& path, std::string_view bytes) {
  LineReader lines(bytes);
  std::string_view line, token;
  auto error = [&](const std::string& what) {
    return Status(ErrorCode::ParseError, path + ":" + std::to_string(lines.number()) + ": " + what);
  };
  bool magic = lines.next(line);
  while (magic && !line.empty() && is_blank(line.back())) line.remove_suffix(1);
  if (!magic || line != "ply") {
    return Status(ErrorCode::ParseError, path + ": not a PLY file (first line is not 'ply')");
  }
  PlyHeader header;
  bool have_format = false;
  while (true) {
    if (!lines.next(line)) return Status(ErrorCode::ParseError, path + ": PLY header has no end_header");
    std::string_view rest = line;
    if (!next_token(rest, token)) continue;
    if (token == "end_header") break;
    if (token == "comment" || token == "obj_info") continue;
    std::string_view a, b, c, d;
    if (token == "format") {
      if (!next_token(rest, a)) return error("format line has no format");
      if (a == "ascii") {
        header.format = PlyFormat::Ascii;
      } else if (a == "binary_little_endian") {
        header.format = PlyFormat::BinaryLE;
      } else if (a == "binary_big_endian") {
        header.format = PlyFormat::BinaryBE;
      } else {
        return error("unknown PLY format " + quote_token(a));
      }
      have_format = true;
    } else if (token == "element") {
      std::int64_t count = 0;
      if (!next_token(rest, a) || !next_token(rest, b) || !parse_int(b, count) || count < 0) {
        return error("bad element line (expected 'element <name> <count>')");
      }
      for (const PlyElement& e : header.elements) {
        if (e.name == a) return error("duplicate element " + quote_token(a));
      }
      header.elements.push_back({std::string(a), static_cast<std::uint64_t>(count), {}});
    } else if (token == "property") {
      if (header.elements.empty()) return error("property before any element");
      PlyProperty p;
      if (!next_token(rest, a)) return error("property line has no type");
      if (a == "list") {
        p.is_list = true;
        if (!next_token(rest, b) || !next_token(rest, c) || !next_token(rest, d)) {
          return error("bad list property (expected 'property list <count type> <item type> <name>')");
        }
        if (!parse_type(b, p.count_type)) return error("unknown property type " + quote_token(b));
        if (!parse_type(c, p.type)) return error("unknown property type " + quote_token(c));
        if (!is_integer(p.count_type)) return error("list count type " + quote_token(b) + " is not an integer type");
        p.name = std::string(d);
      } else {
        if (!parse_type(a, p.type)) return error("unknown property type " + quote_token(a));
        if (!next_token(rest, b)) return error("property has no name");
        p.name = std::string(b);
      }
      header.elements.back().properties.push_back(std::move(p));
    } else {
      double number = 0;
      if (parse_double(token, number)) return error("PLY header has no end_header line before the data");
      return error("unknown PLY header line " + quote_token(token));
    }
  }
  if (!have_format) return Status(ErrorCode::ParseError, path + ": PLY header has no format line");
  header.body_offset = bytes.size() - lines.remaining_bytes();
  header.body_line = lines.number() + 1;
  return header;
}

/// What a property means to us.
enum class Role { Skip, X, Y, Z, FaceIndices, Red, Green, Blue };

/// Colour integers are fractions of their type's largest value (uchar 255 = 1.0).
double color_scale(PlyType t) {
  switch (t) {
    case PlyType::Int8:
    case PlyType::UInt8: return 1.0 / 255;
    case PlyType::Int16:
    case PlyType::UInt16: return 1.0 / 65535;
    case PlyType::Int32:
    case PlyType::UInt32: return 1.0 / 4294967295.0;
    case PlyType::Float32:
    case PlyType::Float64: return 1.0;
  }
  return 1.0;
}

enum class ReadResult { Ok, End, Bad };

/// Reads values from a binary body.
class BinarySource {
 public:
  static constexpr bool kBinary = true;
  BinarySource(std::string_view body, bool big_endian) : in_(body.data(), body.size()), big_(big_endian) {}

  ReadResult real(PlyType t, double& v) {
    bool ok = true;
    switch (t) {
      case PlyType::Float32: { float f; ok = in_.read(f, big_); v = f; break; }
      case PlyType::Float64: ok = in_.read(v, big_); break;
      default: {
        std::int64_t i = 0;
        ReadResult r = integer(t, i);
        v = static_cast<double>(i);
        return r;
      }
    }
    return ok ? ReadResult::Ok : ReadResult::End;
  }
  ReadResult integer(PlyType t, std::int64_t& v) {
    bool ok = true;
    switch (t) {
      case PlyType::Int8: { std::int8_t x; ok = in_.read(x, big_); v = x; break; }
      case PlyType::UInt8: { std::uint8_t x; ok = in_.read(x, big_); v = x; break; }
      case PlyType::Int16: { std::int16_t x; ok = in_.read(x, big_); v = x; break; }
      case PlyType::UInt16: { std::uint16_t x; ok = in_.read(x, big_); v = x; break; }
      case PlyType::Int32: { std::int32_t x; ok = in_.read(x, big_); v = x; break; }
      case PlyType::UInt32: { std::uint32_t x; ok = in_.read(x, big_); v = x; break; }
      default: return ReadResult::Bad;  // the header check only lets integer types get here
    }
    return ok ? ReadResult::Ok : ReadResult::End;
  }
  ReadResult skip(PlyType t, std::uint64_t n = 1) {
    const std::uint64_t size = type_size(t);
    if (n > in_.remaining() / size) return ReadResult::End;
    in_.skip(static_cast<std::size_t>(n * size));
    return ReadResult::Ok;
  }
  std::size_t bytes_left() const { return in_.remaining(); }
  std::string bad_message(const std::string& path) const { return path + ": bad binary value"; }

  /// Bytes after the last element. Stray trailing whitespace (a final newline some writers
  /// add) is tolerated; anything else means the header's counts are wrong.
  std::size_t trailing_data(std::string_view body) const {
    std::size_t start = body.size() - in_.remaining();
    for (std::size_t i = start; i < body.size(); ++i) {
      if (!is_blank(body[i]) && body[i] != '\n' && body[i] != '\0') return body.size() - start;
    }
    return 0;
  }

 private:
  ByteReader in_;
  bool big_;
};

/// Reads values from an ascii body: a whitespace-separated token stream.
class AsciiSource {
 public:
  static constexpr bool kBinary = false;
  AsciiSource(std::string_view body, std::uint64_t first_line) : tokens_(body), line_offset_(first_line - 1) {}

  ReadResult real(PlyType, double& v) {
    if (!tokens_.next(last_)) return ReadResult::End;
    return parse_double(last_, v) ? ReadResult::Ok : ReadResult::Bad;
  }
  ReadResult integer(PlyType, std::int64_t& v) {
    if (!tokens_.next(last_)) return ReadResult::End;
    return parse_int(last_, v) ? ReadResult::Ok : ReadResult::Bad;
  }
  ReadResult skip(PlyType t, std::uint64_t n = 1) {
    double ignored;
    for (std::uint64_t i = 0; i < n; ++i) {
      ReadResult r = real(t, ignored);
      if (r != ReadResult::Ok) return r;
    }
    return ReadResult::Ok;
  }
  std::size_t bytes_left() const { return tokens_.remaining_bytes(); }
  std::string bad_message(const std::string& path) const {
    return path + ":" + std::to_string(line()) + ": bad number " + quote_token(last_);
  }
  bool has_trailing_data() { return tokens_.next(last_); }
  std::uint64_t line() const { return tokens_.line() + line_offset_; }
  /// Whether the element just read ended its line (see read_body's `misaligned`).
  bool element_ends_line() const { return tokens_.rest_of_line_blank(); }

 private:
  TokenReader tokens_;
  std::uint64_t line_offset_;
  std::string_view last_;
};

std::string plural(const PlyElement& e) {
  if (e.name == "vertex") return "vertices";
  if (e.name == "face") return "faces";
  return "'" + e.name + "' elements";
}

/// The smallest number of bytes one element can take (ascii: one digit and one separator
/// per value); used to clamp reserves, so header counts never decide an allocation alone.
std::size_t min_element_size(const PlyElement& e, bool binary) {
  std::size_t size = 0;
  for (const PlyProperty& p : e.properties) size += binary ? type_size(p.is_list ? p.count_type : p.type) : 2;
  return size;
}

/// Ascii PLY writers put one element per line. The first element that does not end its line
/// is remembered: when reading then fails, a header whose counts or properties do not match
/// the data is the likely cause, and the place where the two part ways is the useful thing to
/// report (the failure itself shows up elements later, as something unrelated).
struct Misalignment {
  bool seen = false;
  std::string message;
};

template <class Source>
Status read_body(const std::string& path, const PlyHeader& header, const char* kind, Source& src,
                 MeshBuilder& builder, Misalignment& misaligned, std::vector<double>* colors) {
  std::vector<std::int64_t> corners;
  std::vector<Role> roles;
  for (const PlyElement& e : header.elements) {
    if (e.properties.empty()) continue;  // occupies no bytes, whatever its count
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    roles.assign(e.properties.size(), Role::Skip);
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const PlyProperty& p = e.properties[k];
      if (is_vertex && !p.is_list && (p.name == "x" || p.name == "y" || p.name == "z")) {
        roles[k] = p.name == "x" ? Role::X : p.name == "y" ? Role::Y : Role::Z;
      } else if (is_face && p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) {
        roles[k] = Role::FaceIndices;
      } else if (colors && is_vertex && !p.is_list && (p.name == "red" || p.name == "green" || p.name == "blue")) {
        roles[k] = p.name == "red" ? Role::Red : p.name == "green" ? Role::Green : Role::Blue;
      }
    }
    const std::size_t fit =
        std::min<std::uint64_t>(e.count, src.bytes_left() / std::max<std::size_t>(1, min_element_size(e, Source::kBinary)));
    if (is_vertex) builder.reserve(fit, 0);
    if (is_face) builder.reserve(0, fit);

    for (std::uint64_t i = 0; i < e.count; ++i) {
      double xyz[3] = {0, 0, 0}, rgb[3] = {0, 0, 0};
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const PlyProperty& p = e.properties[k];
        ReadResult r = ReadResult::Ok;
        if (p.is_list) {
          std::int64_t n = 0;
          r = src.integer(p.count_type, n);
          if (r == ReadResult::Ok && n < 0) {
            return Status(ErrorCode::ParseError, path + ": " + e.name + " " + std::to_string(i) +
                                                     " has a negative list length " + std::to_string(n));
          }
          if (r == ReadResult::Ok && roles[k] == Role::FaceIndices) {
            corners.clear();
            for (std::int64_t c = 0; c < n && r == ReadResult::Ok; ++c) {
              std::int64_t index = 0;
              r = src.integer(p.type, index);
              corners.push_back(index);
            }
          } else if (r == ReadResult::Ok) {
            r = src.skip(p.type, static_cast<std::uint64_t>(n));
          }
        } else if (roles[k] == Role::Red || roles[k] == Role::Green || roles[k] == Role::Blue) {
          double& c = rgb[static_cast<int>(roles[k]) - static_cast<int>(Role::Red)];
          r = src.real(p.type, c);
          c *= color_scale(p.type);
        } else if (roles[k] != Role::Skip) {
          r = src.real(p.type, xyz[static_cast<int>(roles[k]) - static_cast<int>(Role::X)]);
        } else {
          r = src.skip(p.type);
        }
        if (r == ReadResult::End) {
          return Status(ErrorCode::ParseError, path + ": " + kind + " PLY ends after " + std::to_string(i) +
                                                   " of " + std::to_string(e.count) + " " + plural(e) +
                                                   " (truncated, or wrong counts in the header?)");
        }
        if (r == ReadResult::Bad) return Status(ErrorCode::ParseError, src.bad_message(path));
      }
      if constexpr (!Source::kBinary) {
        if (!misaligned.seen && !src.element_ends_line()) {
          misaligned.seen = true;
          misaligned.message = path + ":" + std::to_string(src.line()) + ": " + e.name + " " + std::to_string(i) +
                               " does not end its line: the data does not match the header (wrong counts or "
                               "properties?)";
        }
      }
      if (is_vertex) SPHEREKIT_RETURN_IF_ERROR(builder.add_vertex(xyz[0], xyz[1], xyz[2]));
      if (is_vertex && colors) colors->insert(colors->end(), rgb, rgb + 3);
      if (is_face) SPHEREKIT_RETURN_IF_ERROR(builder.add_face(corners.data(), corners.size(), FaceSource::element(i)));
    }
  }
  return {};
}

/// Header-level checks that need the whole header: x/y/z and the index list must exist.
Status check_layout(const std::string& path, const PlyHeader& header) {
  const PlyElement* vertex = nullptr;
  for (const PlyElement& e : header.elements) {
    if (e.name == "vertex") vertex = &e;
    if (e.name != "face") continue;
    const PlyProperty* list = nullptr;
    for (const PlyProperty& p : e.properties) {
      if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) list = &p;
    }
    if (!list) return Status(ErrorCode::ParseError, path + ": face element has no 'vertex_indices' list");
    if (!is_integer(list->type)) {
      return Status(ErrorCode::ParseError, path + ": face vertex_indices list has a non-integer item type");
    }
  }
  if (!vertex) return Status(ErrorCode::ParseError, path + ": PLY has no vertex element");
  for (const char* axis : {"x", "y", "z"}) {
    bool found = false;
    for (const PlyProperty& p : vertex->properties) found = found || (!p.is_list && p.name == axis);
    if (!found) return Status(ErrorCode::ParseError, path + ": vertex element has no '" + axis + "' property");
  }
  return {};
}

}  // namespace

Result<TriMesh> read_ply(const std::string& path, std::string_view bytes, const ReadOptions& options,
                         ReadInfo& info, MeshAttributes* attributes) {
  SPHEREKIT_ASSIGN_OR_RETURN(PlyHeader header, parse_header(path, bytes));
  SPHEREKIT_RETURN_IF_ERROR(check_layout(path, header));
  const std::string_view body = bytes.substr(header.body_offset);
  MeshBuilder builder(path, options.polygons);
  // Colours only if the vertex element has all three channels.
  std::vector<double> colors;
  int channels = 0;
  for (const PlyElement& e : header.elements) {
    if (e.name != "vertex") continue;
    for (const PlyProperty& p : e.properties)
      channels += !p.is_list && (p.name == "red" || p.name == "green" || p.name == "blue");
  }
  std::vector<double>* want_colors = attributes && channels == 3 ? &colors : nullptr;
  if (header.format == PlyFormat::Ascii) {
    info.format = "ply-ascii";
    AsciiSource src(body, header.body_line);
    Misalignment misaligned;
    Status read = read_body(path, header, "ascii", src, builder, misaligned, want_colors);
    if (read.ok() && src.has_trailing_data()) {
      read = Status(ErrorCode::ParseError, path + ":" + std::to_string(src.line()) +
                                               ": data after the last element (wrong counts in header?)");
    }
    if (!read.ok()) return misaligned.seen ? Status(ErrorCode::ParseError, misaligned.message) : read;
  } else {
    const bool big = header.format == PlyFormat::BinaryBE;
    info.format = big ? "ply-binary-be" : "ply-binary-le";
    BinarySource src(body, big);
    Misalignment unused;  // binary data has no lines
    SPHEREKIT_RETURN_IF_ERROR(read_body(path, header, "binary", src, builder, unused, want_colors));
    if (std::size_t extra = src.trailing_data(body)) {
      return Status(ErrorCode::ParseError, path + ": binary PLY has " + std::to_string(extra) +
                                               " bytes after the last element (wrong counts in header?)");
    }
  }
  SPHEREKIT_ASSIGN_OR_RETURN(TriMesh mesh, builder.finish(info));
  if (want_colors && static_cast<Eigen::Index>(colors.size()) == 3 * mesh.V.rows()) {
    // Float colour channels can hold inf or nan: not a colour (fuzz finding, as for OBJ).
    for (std::size_t i = 0; i < colors.size(); ++i)
      if (!std::isfinite(colors[i]))
        return Status(ErrorCode::ParseError, path + ": vertex " + std::to_string(i / 3) + " has a non-finite colour");
    attributes->colors = Eigen::Map<const RowMat3d>(colors.data(), mesh.V.rows(), 3);
  }
  return mesh;
}

std::string format_ply(const TriMesh& mesh, bool binary, int precision, const MeshAttributes* attributes) {
  const bool colors = attributes && attributes->colors.rows() == mesh.V.rows() && mesh.V.rows() > 0;
  // 0..1 -> 0..255, rounded to nearest and clamped (what viewers expect from uchar colours).
  auto channel = [&](std::size_t i, int k) {
    const double c = attributes->colors(static_cast<Eigen::Index>(i), k) * 255.0 + 0.5;
    return static_cast<std::uint8_t>(c <= 0 ? 0 : c >= 255 ? 255 : c);
  };
  const auto nv = static_cast<std::size_t>(mesh.V.rows()), nf = static_cast<std::size_t>(mesh.F.rows());
  std::string out = "ply\nformat ";
  out += binary ? "binary_little_endian 1.0\n" : "ascii 1.0\n";
  out += std::string("comment written by spherekit ") + kVersion + "\n";
  out += "element vertex " + std::to_string(nv) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  if (colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += "element face " + std::to_string(nf) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";
  if (binary) {
    out.reserve(out.size() + nv * 24 + nf * 13);
    for (std::size_t i = 0; i < nv; ++i) {
      for (int k = 0; k < 3; ++k) append_le(out, mesh.V(static_cast<Eigen::Index>(i), k));
      for (int k = 0; colors && k < 3; ++k) append_le(out, channel(i, k));
    }
    for (std::size_t i = 0; i < nf; ++i) {
      append_le(out, std::uint8_t{3});
      for (int k = 0; k < 3; ++k) append_le(out, mesh.F(static_cast<Eigen::Index>(i), k));
    }
    return out;
  }
  out.reserve(out.size() + nv * 64 + nf * 24);
  for (std::size_t i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) {
      if (k) out += ' ';
      append_double(out, mesh.V(static_cast<Eigen::Index>(i), k), precision);
    }
    for (int k = 0; colors && k < 3; ++k) {
      out += ' ';
      append_int(out, channel(i, k));
    }
    out += '\n';
  }
  for (std::size_t i = 0; i < nf; ++i) {
    out += '3';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_int(out, mesh.F(static_cast<Eigen::Index>(i), k));
    }
    out += '\n';
  }
  return out;
}

}  // namespace spherekit::formats::detail
