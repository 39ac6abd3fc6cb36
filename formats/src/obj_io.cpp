// Wavefront OBJ: `v x y z` and `f` lines. Texture coordinates, normals, groups, materials
// and every other statement are skipped: a parameterization needs positions and triangles.
// Face corners may be `i`, `i/t`, `i/t/n` or `i//n`; negative indices count back from the
// last vertex defined so far (OBJ's relative indices).
#include <string>
#include <vector>

#include "mesh_builder.h"
#include "mesh_codecs.h"
#include "number_text.h"
#include "text_scan.h"

namespace spherekit::formats::detail {
namespace {

std::string at_line(const std::string& path, std::uint64_t line) {
  return path + ":" + std::to_string(line) + ": ";
}

}  // namespace

Result<TriMesh> read_obj(const std::string& path, std::string_view bytes, const ReadOptions& options,
                         ReadInfo& info) {
  info.format = "obj";
  // OBJ readers skip statements they do not know, so a binary file (or UTF-16 text) would
  // otherwise end as a puzzling "no faces".
  if (const std::size_t nul = bytes.find('\0'); nul != std::string_view::npos) {
    return Status(ErrorCode::ParseError, path + ": not a text file (NUL byte at offset " + std::to_string(nul) + ")");
  }
  MeshBuilder builder(path, options.polygons, /*index_base=*/1);
  // A typical OBJ spends ~30 bytes per vertex line and ~2 face lines per vertex; this avoids
  // most regrowth without trusting anything the file claims.
  builder.reserve(bytes.size() / 80, bytes.size() / 40);
  LineReader lines(bytes);
  std::vector<std::int64_t> corners;
  std::string_view line, token;
  while (lines.next(line)) {
    std::string_view rest = line;
    if (!next_token(rest, token)) continue;
    if (token == "v") {
      double xyz[3];
      for (double& c : xyz) {
        if (!next_token(rest, token)) {
          return Status(ErrorCode::ParseError, at_line(path, lines.number()) + "vertex has fewer than 3 coordinates");
        }
        if (!parse_double(token, c)) {
          return Status(ErrorCode::ParseError, at_line(path, lines.number()) + "bad number " + quote_token(token));
        }
      }
      // Anything after z (w, or r g b vertex colours) is ignored.
      SPHEREKIT_RETURN_IF_ERROR(builder.add_vertex(xyz[0], xyz[1], xyz[2]));
    } else if (token == "f") {
      corners.clear();
      while (next_token(rest, token) && token.front() != '#') {
        std::string_view index_text = token.substr(0, token.find('/'));
        std::int64_t index = 0;
        if (!parse_int(index_text, index)) {
          return Status(ErrorCode::ParseError, at_line(path, lines.number()) + "bad face corner " + quote_token(token));
        }
        const std::int64_t nv = builder.num_vertices();
        if (index == 0 || (index < 0 && index < -nv)) {
          return Status(ErrorCode::InvalidInput, at_line(path, lines.number()) + "face index " +
                                                     std::to_string(index) + " out of range (" +
                                                     std::to_string(nv) + " vertices)");
        }
        corners.push_back(index > 0 ? index - 1 : nv + index);
      }
      SPHEREKIT_RETURN_IF_ERROR(builder.add_face(corners.data(), corners.size(), FaceSource::line(lines.number())));
    }
  }
  return builder.finish(info);
}

std::string format_obj(const TriMesh& mesh, int precision, const std::string& header) {
  std::string out = header;
  out.reserve(header.size() + static_cast<std::size_t>(mesh.V.rows()) * 64 +
              static_cast<std::size_t>(mesh.F.rows()) * 24);
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    out += "v";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_double(out, mesh.V(i, k), precision);
    }
    out += '\n';
  }
  for (Eigen::Index i = 0; i < mesh.F.rows(); ++i) {
    out += "f";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_int(out, std::int64_t{mesh.F(i, k)} + 1);
    }
    out += '\n';
  }
  return out;
}

}  // namespace spherekit::formats::detail
