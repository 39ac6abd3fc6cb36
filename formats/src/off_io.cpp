// Object File Format (Geomview OFF): an optional `OFF` keyword (COFF, NOFF, CNOFF, STOFF...:
// the extra per-vertex colours, normals and texture coordinates are skipped), then
// `#vertices #faces [#edges]`, one vertex per line and one `n i1 ... in [colour]` face per
// line, 0-based. '#' starts a comment anywhere. Read line by line because the number of
// trailing values per line (colours) is not declared.
#include <string>
#include <vector>

#include "mesh_builder.h"
#include "mesh_codecs.h"
#include "text_scan.h"

namespace spherekit::formats::detail {
namespace {

/// The next line with content (comments and blank lines skipped).
bool next_content(LineReader& lines, std::string_view& content) {
  std::string_view line;
  while (lines.next(line)) {
    content = strip_comment(line);
    if (!content.empty()) return true;
  }
  return false;
}

}  // namespace

Result<TriMesh> read_off(const std::string& path, std::string_view bytes, const ReadOptions& options,
                         ReadInfo& info) {
  info.format = "off";
  LineReader lines(bytes);
  auto at = [&](const std::string& what) { return path + ":" + std::to_string(lines.number()) + ": " + what; };
  std::string_view content, rest, token;
  if (!next_content(lines, content)) return Status(ErrorCode::ParseError, path + ": OFF file has no header");
  rest = content;
  next_token(rest, token);
  std::int64_t ignored = 0;
  if (token.size() >= 3 && token.substr(token.size() - 3) == "OFF") {
    std::string_view prefix = token.substr(0, token.size() - 3);
    if (prefix.find_first_of("4n") != std::string_view::npos) {
      return Status(ErrorCode::Unsupported, at(quote_token(token) + " (4-D or n-D OFF) is not supported"));
    }
    if (prefix.find_first_not_of("STCN") != std::string_view::npos) {
      return Status(ErrorCode::ParseError, at("unknown OFF keyword " + quote_token(token)));
    }
    // The counts usually follow on the next line, but may share the keyword's line.
    std::string_view probe = rest;
    if (next_token(probe, token) && token == "BINARY") {
      return Status(ErrorCode::Unsupported, at("binary OFF is not supported"));
    }
    probe = rest;
    if (!next_token(probe, token)) {
      if (!next_content(lines, content)) return Status(ErrorCode::ParseError, path + ": OFF file has no counts line");
      rest = content;
    }
  } else if (parse_int(token, ignored)) {
    rest = content;  // no keyword: the first line holds the counts (allowed by the format)
  } else {
    return Status(ErrorCode::ParseError, at("not an OFF file (starts with " + quote_token(token) + ")"));
  }

  std::int64_t counts[2] = {0, 0};
  for (std::int64_t& c : counts) {
    if (!next_token(rest, token) || !parse_int(token, c) || c < 0) {
      return Status(ErrorCode::ParseError, at("bad counts line (expected '#vertices #faces #edges')"));
    }
  }
  const auto nv = static_cast<std::uint64_t>(counts[0]), nf = static_cast<std::uint64_t>(counts[1]);
  MeshBuilder builder(path, options.polygons);
  // At least "0 0 0\n" (6 bytes) per vertex and "3 0 0 0\n" (8 bytes) per face.
  builder.reserve(std::min<std::uint64_t>(nv, lines.remaining_bytes() / 6),
                  std::min<std::uint64_t>(nf, lines.remaining_bytes() / 8));

  for (std::uint64_t i = 0; i < nv; ++i) {
    if (!next_content(lines, content)) {
      return Status(ErrorCode::ParseError, path + ": OFF ends after " + std::to_string(i) + " of " +
                                               std::to_string(nv) +
                                               " vertices (truncated, or wrong counts in the header?)");
    }
    rest = content;
    double xyz[3];
    for (double& c : xyz) {
      if (!next_token(rest, token)) return Status(ErrorCode::ParseError, at("vertex has fewer than 3 coordinates"));
      if (!parse_double(token, c)) return Status(ErrorCode::ParseError, at("bad number " + quote_token(token)));
    }
    SPHEREKIT_RETURN_IF_ERROR(builder.add_vertex(xyz[0], xyz[1], xyz[2]));
  }

  std::vector<std::int64_t> corners;
  for (std::uint64_t i = 0; i < nf; ++i) {
    if (!next_content(lines, content)) {
      return Status(ErrorCode::ParseError, path + ": OFF ends after " + std::to_string(i) + " of " +
                                               std::to_string(nf) +
                                               " faces (truncated, or wrong counts in the header?)");
    }
    rest = content;
    std::int64_t n = 0;
    next_token(rest, token);
    if (!parse_int(token, n) || n < 0) return Status(ErrorCode::ParseError, at("bad corner count " + quote_token(token)));
    corners.clear();
    for (std::int64_t k = 0; k < n; ++k) {
      std::int64_t index = 0;
      if (!next_token(rest, token)) {
        return Status(ErrorCode::ParseError, at("face lists " + std::to_string(n) + " corners but has only " +
                                                std::to_string(k) + " indices"));
      }
      if (!parse_int(token, index)) return Status(ErrorCode::ParseError, at("bad vertex index " + quote_token(token)));
      corners.push_back(index);
    }
    // Values after the indices are a face colour: ignored.
    SPHEREKIT_RETURN_IF_ERROR(builder.add_face(corners.data(), corners.size(), FaceSource::line(lines.number())));
  }
  if (next_content(lines, content)) {
    return Status(ErrorCode::ParseError, at("data after the last face (wrong counts in header?)"));
  }
  return builder.finish(info);
}

}  // namespace spherekit::formats::detail
