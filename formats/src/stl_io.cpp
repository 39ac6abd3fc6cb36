// STL, ascii and binary. STL stores three positions per triangle and no sharing, so the
// vertices are welded by exact position (weld.h) to recover an indexed mesh.
//
// Telling the two apart: binary files may also begin with "solid" (many exporters write
// it into the 80-byte header), so a file is binary when its size is exactly
// 84 + 50 * (triangle count at byte 80), or when it does not look like text.
#include <string>
#include <vector>

#include "byte_reader.h"
#include "mesh_builder.h"
#include "mesh_codecs.h"
#include "text_scan.h"
#include "weld.h"

namespace spherekit::formats::detail {
namespace {

constexpr std::size_t kHeaderBytes = 84;    // 80-byte header + uint32 triangle count
constexpr std::size_t kTriangleBytes = 50;  // normal, 3 vertices (12 floats) + uint16 attribute

Result<TriMesh> read_binary_stl(const std::string& path, std::string_view bytes, const ReadOptions& options,
                                ReadInfo& info) {
  info.format = "stl-binary";
  if (bytes.size() < kHeaderBytes) {
    return Status(ErrorCode::ParseError, path + ": too short for a binary STL (" + std::to_string(bytes.size()) +
                                             " bytes, the header alone has 84)");
  }
  const std::uint64_t count = load_scalar<std::uint32_t>(bytes.data() + 80, false);
  const std::uint64_t fit = (bytes.size() - kHeaderBytes) / kTriangleBytes;
  if (fit < count) {
    return Status(ErrorCode::ParseError, path + ": binary STL ends after " + std::to_string(fit) + " of " +
                                             std::to_string(count) + " triangles");
  }
  // Extra bytes after the last triangle are tolerated: some exporters pad the file.
  MeshBuilder builder(path, options.polygons);
  builder.reserve(count / 2 + 2, count);  // closed meshes have about half as many vertices as faces
  PositionWelder welder(builder);
  welder.reserve(count / 2 + 2);
  ByteReader in(bytes.data() + kHeaderBytes, count * kTriangleBytes);
  for (std::uint64_t t = 0; t < count; ++t) {
    in.skip(12);  // facet normal: recomputed from the vertices by whoever needs it
    std::int64_t corners[3];
    for (std::int64_t& c : corners) {
      float xyz[3];
      for (float& v : xyz) in.read(v, false);
      SPHEREKIT_RETURN_IF_ERROR(welder.add(xyz[0], xyz[1], xyz[2], c));
    }
    in.skip(2);  // attribute byte count (sometimes a colour): unused
    SPHEREKIT_RETURN_IF_ERROR(builder.add_face(corners, 3, FaceSource::element(t)));
  }
  return builder.finish(info);
}

Result<TriMesh> read_ascii_stl(const std::string& path, std::string_view bytes, const ReadOptions& options,
                               ReadInfo& info) {
  info.format = "stl-ascii";
  TokenReader tokens(bytes);
  std::string_view token;
  std::uint64_t facet = 0;
  auto at = [&](const std::string& what) {
    return Status(ErrorCode::ParseError, path + ":" + std::to_string(tokens.line()) + ": " + what);
  };
  auto truncated = [&]() {
    return Status(ErrorCode::ParseError,
                  path + ": ascii STL ends inside facet " + std::to_string(facet) + " (truncated?)");
  };
  // Reads the next token and requires it to be `word` (any case).
  auto expect = [&](const char* word) -> Status {
    if (!tokens.next(token)) return truncated();
    if (!iequals(token, word)) return at(std::string("expected '") + word + "', got " + quote_token(token));
    return {};
  };
  auto number = [&](double& v) -> Status {
    if (!tokens.next(token)) return truncated();
    if (!parse_double(token, v)) return at("bad number " + quote_token(token));
    return {};
  };

  MeshBuilder builder(path, options.polygons);
  PositionWelder welder(builder);
  std::vector<std::int64_t> corners;
  tokens.next(token);  // "solid", checked by the caller
  tokens.skip_line();  // the solid's name may contain spaces
  while (true) {
    if (!tokens.next(token)) {
      return Status(ErrorCode::ParseError, path + ": ascii STL has no 'endsolid' (truncated?)");
    }
    if (iequals(token, "endsolid")) {
      tokens.skip_line();
      // Some tools concatenate several solids in one file.
      if (!tokens.next(token)) break;
      if (!iequals(token, "solid")) return at("data after 'endsolid': " + quote_token(token));
      tokens.skip_line();
      continue;
    }
    if (!iequals(token, "facet")) return at("expected 'facet' or 'endsolid', got " + quote_token(token));
    const std::uint64_t facet_line = tokens.line();
    if (!tokens.next(token)) return truncated();
    if (iequals(token, "normal")) {
      double ignored;  // the normal is recomputed by whoever needs it
      for (int k = 0; k < 3; ++k) SPHEREKIT_RETURN_IF_ERROR(number(ignored));
      SPHEREKIT_RETURN_IF_ERROR(expect("outer"));
    } else if (!iequals(token, "outer")) {
      return at("expected 'normal' or 'outer', got " + quote_token(token));
    }
    SPHEREKIT_RETURN_IF_ERROR(expect("loop"));
    corners.clear();
    while (true) {
      if (!tokens.next(token)) return truncated();
      if (iequals(token, "endloop")) break;
      if (!iequals(token, "vertex")) return at("expected 'vertex' or 'endloop', got " + quote_token(token));
      double xyz[3];
      for (double& v : xyz) SPHEREKIT_RETURN_IF_ERROR(number(v));
      std::int64_t index = 0;
      SPHEREKIT_RETURN_IF_ERROR(welder.add(xyz[0], xyz[1], xyz[2], index));
      corners.push_back(index);
    }
    SPHEREKIT_RETURN_IF_ERROR(expect("endfacet"));
    SPHEREKIT_RETURN_IF_ERROR(builder.add_face(corners.data(), corners.size(), FaceSource::line(facet_line)));
    ++facet;
  }
  return builder.finish(info);
}

/// Text that starts with "solid" and has no NUL byte: binary STLs are full of zeros.
bool looks_like_ascii(std::string_view bytes) {
  std::size_t i = 0;
  while (i < bytes.size() && (is_blank(bytes[i]) || bytes[i] == '\n')) ++i;
  if (!iequals(bytes.substr(i, 5), "solid")) return false;
  return bytes.find('\0') == std::string_view::npos;
}

}  // namespace

Result<TriMesh> read_stl(const std::string& path, std::string_view bytes, const ReadOptions& options,
                         ReadInfo& info) {
  if (bytes.size() >= kHeaderBytes) {
    const std::uint64_t count = load_scalar<std::uint32_t>(bytes.data() + 80, false);
    if (kHeaderBytes + kTriangleBytes * count == bytes.size()) return read_binary_stl(path, bytes, options, info);
  }
  if (looks_like_ascii(bytes)) return read_ascii_stl(path, bytes, options, info);
  return read_binary_stl(path, bytes, options, info);
}

}  // namespace spherekit::formats::detail
