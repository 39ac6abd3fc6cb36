// Wavefront OBJ: `v x y z` and `f` lines. Normals, groups and every other statement are
// skipped: a parameterization needs positions and triangles. When the caller asks for
// attributes (mesh_attributes.h), `v x y z r g b` colours, `vt` texture coordinates with the
// corners' texture indices, `mtllib` and the first `usemtl` are kept too.
// Face corners may be `i`, `i/t`, `i/t/n` or `i//n`; negative indices count back from the
// last vertex (texture coordinate) defined so far (OBJ's relative indices).
#include <cmath>
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
                         ReadInfo& info, MeshAttributes* attributes) {
  info.format = "obj";
  // OBJ readers skip statements they do not know, so a binary file (or UTF-16 text) would
  // otherwise end as a puzzling "no faces".
  if (const std::size_t nul = bytes.find('\0'); nul != std::string_view::npos) {
    return Status(ErrorCode::ParseError, path + ": not a text file (NUL byte at offset " + std::to_string(nul) + ")");
  }
  MeshBuilder builder(path, options.polygons, /*index_base=*/1);
  if (attributes) builder.enable_corner_channel();
  // A typical OBJ spends ~30 bytes per vertex line and ~2 face lines per vertex; this avoids
  // most regrowth without trusting anything the file claims.
  builder.reserve(bytes.size() / 80, bytes.size() / 40);
  LineReader lines(bytes);
  std::vector<std::int64_t> corners;
  // Attributes (only collected when asked for): colours per vertex, texture coordinates,
  // the texture index of every face corner (the builder triangulates them with the faces),
  // and whether some corner had none (then FT is not set).
  std::vector<double> colors, uv;
  std::vector<std::int64_t> tex;
  std::int64_t colored_vertices = 0;
  bool corner_without_uv = false;
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
      // After z: nothing, w, or r g b vertex colours (kept when attributes are asked for).
      if (attributes) {
        double extra[4];
        int n = 0;
        while (n < 4 && next_token(rest, token) && token.front() != '#' && parse_double(token, extra[n])) ++n;
        if (n == 3) {
          // A colour of inf or nan (or an overflowing 1e400) is not a colour (fuzz finding).
          if (!std::isfinite(extra[0]) || !std::isfinite(extra[1]) || !std::isfinite(extra[2]))
            return Status(ErrorCode::ParseError, at_line(path, lines.number()) + "vertex colour is not finite");
          colors.resize(3 * static_cast<std::size_t>(builder.num_vertices()), 0.0);
          colors.insert(colors.end(), extra, extra + 3);
          ++colored_vertices;
        }
      }
      SPHEREKIT_RETURN_IF_ERROR(builder.add_vertex(xyz[0], xyz[1], xyz[2]));
    } else if (attributes && token == "vt") {
      double st[2] = {0, 0};
      for (int k = 0; k < 2; ++k) {
        if (!next_token(rest, token) || token.front() == '#') {
          if (k == 0) return Status(ErrorCode::ParseError, at_line(path, lines.number()) + "texture coordinate has no value");
          break;
        }
        if (!parse_double(token, st[k]))
          return Status(ErrorCode::ParseError, at_line(path, lines.number()) + "bad number " + quote_token(token));
        if (!std::isfinite(st[k]))
          return Status(ErrorCode::ParseError, at_line(path, lines.number()) + "texture coordinate is not finite");
      }
      uv.insert(uv.end(), st, st + 2);
    } else if (attributes && token == "mtllib") {
      while (next_token(rest, token) && token.front() != '#') attributes->material_libraries.emplace_back(token);
    } else if (attributes && token == "usemtl") {
      if (attributes->material.empty() && next_token(rest, token)) attributes->material = std::string(token);
    } else if (token == "f") {
      corners.clear();
      tex.clear();
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
        if (attributes) {
          const std::size_t slash = token.find('/');
          std::string_view t = slash == std::string_view::npos ? std::string_view() : token.substr(slash + 1);
          t = t.substr(0, t.find('/'));
          std::int64_t ti = 0;
          const auto nt = static_cast<std::int64_t>(uv.size() / 2);
          if (t.empty()) {
            corner_without_uv = true;
          } else if (!parse_int(t, ti) || ti == 0 || (ti < 0 && ti < -nt)) {
            return Status(ErrorCode::ParseError, at_line(path, lines.number()) + "bad texture index in corner " +
                                                     quote_token(token));
          } else {
            tex.push_back(ti > 0 ? ti - 1 : nt + ti);
          }
        }
      }
      const bool has_tex = attributes && tex.size() == corners.size();
      SPHEREKIT_RETURN_IF_ERROR(builder.add_face(corners.data(), corners.size(), FaceSource::line(lines.number()),
                                                 has_tex ? tex.data() : nullptr));
    }
  }
  SPHEREKIT_ASSIGN_OR_RETURN(TriMesh mesh, builder.finish(info));
  if (attributes) {
    const std::vector<std::int64_t> tex_corners = builder.corner_channel();
    if (colored_vertices > 0 && colored_vertices != mesh.V.rows())
      return Status(ErrorCode::ParseError, path + ": " + std::to_string(colored_vertices) + " of " +
                                               std::to_string(mesh.V.rows()) + " vertices have colours (all or none)");
    if (colored_vertices > 0) attributes->colors = Eigen::Map<const RowMat3d>(colors.data(), mesh.V.rows(), 3);
    // Texture coordinates come with the corners that use them, or not at all: coordinates no
    // face refers to cannot be written back (an OBJ `vt` is only reachable from an `f`), so a
    // round trip would silently lose them (found by the attributes fuzz harness).
    const auto nt = static_cast<Eigen::Index>(uv.size() / 2);
    if (!corner_without_uv && nt > 0 && static_cast<Eigen::Index>(tex_corners.size()) == 3 * mesh.F.rows()) {
      attributes->UV = Eigen::Map<const RowMat2d>(uv.data(), nt, 2);
      for (const std::int64_t t : tex_corners) {
        if (t < 0 || t >= nt)
          return Status(ErrorCode::ParseError, path + ": texture index " + std::to_string(t + 1) + " out of range (" +
                                                   std::to_string(nt) + " texture coordinates)");
      }
      attributes->FT.resize(mesh.F.rows(), 3);
      for (Eigen::Index i = 0; i < attributes->FT.size(); ++i)
        attributes->FT.data()[i] = static_cast<std::int32_t>(tex_corners[static_cast<std::size_t>(i)]);
    }
  }
  return mesh;
}

std::string format_obj(const TriMesh& mesh, int precision, const std::string& header,
                       const MeshAttributes* attributes) {
  std::string out = header;
  const bool colors = attributes && attributes->colors.rows() == mesh.V.rows() && mesh.V.rows() > 0;
  const bool uv = attributes && attributes->FT.rows() == mesh.F.rows() && attributes->UV.rows() > 0;
  const bool normals = attributes && attributes->normals.rows() == mesh.V.rows() && mesh.V.rows() > 0;
  if (attributes) {
    for (const std::string& lib : attributes->material_libraries) out += "mtllib " + lib + "\n";
  }
  out.reserve(header.size() + static_cast<std::size_t>(mesh.V.rows()) * 64 +
              static_cast<std::size_t>(mesh.F.rows()) * 24);
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    out += "v";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_double(out, mesh.V(i, k), precision);
    }
    for (int k = 0; colors && k < 3; ++k) {
      out += ' ';
      append_double(out, attributes->colors(i, k), precision);
    }
    out += '\n';
  }
  for (Eigen::Index i = 0; uv && i < attributes->UV.rows(); ++i) {
    out += "vt ";
    append_double(out, attributes->UV(i, 0), precision);
    out += ' ';
    append_double(out, attributes->UV(i, 1), precision);
    out += '\n';
  }
  for (Eigen::Index i = 0; normals && i < mesh.V.rows(); ++i) {
    out += "vn";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_double(out, attributes->normals(i, k), precision);
    }
    out += '\n';
  }
  if (attributes && !attributes->material.empty()) out += "usemtl " + attributes->material + "\n";
  for (Eigen::Index i = 0; i < mesh.F.rows(); ++i) {
    out += "f";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_int(out, std::int64_t{mesh.F(i, k)} + 1);
      if (uv || normals) out += '/';
      if (uv) append_int(out, std::int64_t{attributes->FT(i, k)} + 1);
      if (normals) {
        out += '/';
        append_int(out, std::int64_t{mesh.F(i, k)} + 1);
      }
    }
    out += '\n';
  }
  return out;
}

}  // namespace spherekit::formats::detail
