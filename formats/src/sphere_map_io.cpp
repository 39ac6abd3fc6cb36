// Sphere maps as OBJ files: the mesh's faces over the sphere points, so any mesh viewer shows
// the map and any mesh reader loads it. Provenance travels in leading comment lines:
//   # spherekit sphere map v1
//   # library_version 0.1.0
//   # method unconstrained
//   # options_digest 3f2a...
//   # seed 1
#include "spherekit/formats/sphere_map_io.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <string_view>

#include "mesh_codecs.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/version.h"
#include "text_scan.h"
#include "unit_vector.h"

namespace spherekit::formats {
namespace {

constexpr std::string_view kMagic = "spherekit sphere map v";

/// Header values are free text; a line break inside one would end the comment early.
std::string header_value(const std::string& s) {
  std::string out = s;
  for (char& c : out) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return out;
}

/// Fills `provenance` from the comment lines before the first statement of an OBJ.
Status parse_provenance(const std::string& path, std::string_view bytes, Provenance& provenance) {
  detail::LineReader lines(bytes);
  std::string_view line;
  while (lines.next(line)) {
    std::string_view rest = line;
    while (!rest.empty() && detail::is_blank(rest.front())) rest.remove_prefix(1);
    if (rest.empty()) continue;
    if (rest.front() != '#') break;  // the header is over
    rest.remove_prefix(1);
    while (!rest.empty() && detail::is_blank(rest.front())) rest.remove_prefix(1);
    while (!rest.empty() && detail::is_blank(rest.back())) rest.remove_suffix(1);
    const std::string at = path + ":" + std::to_string(lines.number()) + ": ";
    if (rest.substr(0, kMagic.size()) == kMagic) {
      std::int64_t version = 0;
      if (!detail::parse_int(rest.substr(kMagic.size()), version) || version < 1) {
        return Status(ErrorCode::ParseError, at + "bad sphere map version " + detail::quote_token(rest));
      }
      if (version > kFormatVersion) {
        return Status(ErrorCode::Unsupported, at + "sphere map format v" + std::to_string(version) +
                                                  " is newer than this library's v" +
                                                  std::to_string(kFormatVersion));
      }
      continue;
    }
    const std::size_t space = rest.find_first_of(" \t");
    const std::string_view key = rest.substr(0, space);
    std::string_view value = space == std::string_view::npos ? std::string_view() : rest.substr(space + 1);
    while (!value.empty() && detail::is_blank(value.front())) value.remove_prefix(1);
    if (key == "library_version") {
      provenance.library_version = std::string(value);
    } else if (key == "method") {
      provenance.method = std::string(value);
    } else if (key == "options_digest") {
      provenance.options_digest = std::string(value);
    } else if (key == "seed") {
      // Seeds use all 64 bits: parse unsigned so values above 2^63 survive.
      std::uint64_t seed = 0;
      auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), seed);
      if (value.empty() || ec != std::errc() || ptr != value.data() + value.size()) {
        return Status(ErrorCode::ParseError, at + "bad seed " + detail::quote_token(value));
      }
      provenance.seed = seed;
    }  // other comments are free text
  }
  return {};
}

}  // namespace

Status check_sphere_map_path(const std::string& path) {
  if (file_extension(path) != "obj") return Status(ErrorCode::Unsupported, path + ": sphere maps are written as .obj files");
  return {};
}

Status write_sphere_map(const std::string& path, const TriMesh& mesh, const SphereMap& map) {
  SPHEREKIT_RETURN_IF_ERROR(check_sphere_map_path(path));
  if (map.S.rows() != mesh.V.rows()) {
    return Status(ErrorCode::InvalidInput, path + ": sphere map has " + std::to_string(map.S.rows()) +
                                               " points, mesh has " + std::to_string(mesh.V.rows()) + " vertices");
  }
  const Provenance& p = map.provenance;
  std::string header = "# " + std::string(kMagic) + std::to_string(kFormatVersion) + "\n";
  header += "# library_version " + header_value(p.library_version.empty() ? kVersion : p.library_version) + "\n";
  header += "# method " + header_value(p.method) + "\n";
  header += "# options_digest " + header_value(p.options_digest) + "\n";
  header += "# seed " + std::to_string(p.seed) + "\n";
  TriMesh sphere;
  sphere.V = map.S;
  sphere.F = mesh.F;
  return write_file_atomic(path, detail::format_obj(sphere, 17, header));
}

namespace detail {

Result<SphereMap> parse_sphere_map(const std::string& path, std::string_view bytes, const TriMesh& mesh) {
  // Unit to within writing precision: dividing by such a norm would only perturb the last
  // bits, so exactly written maps are returned bit-identical.
  constexpr double kUnitRoundoff = 4 * std::numeric_limits<double>::epsilon();
  SPHEREKIT_ASSIGN_OR_RETURN(TriMesh points, detail::parse_mesh(path, bytes, ReadOptions{}, nullptr));
  if (points.V.rows() != mesh.V.rows()) {
    return Status(ErrorCode::InvalidInput, path + ": has " + std::to_string(points.V.rows()) + " vertices, mesh has " +
                                               std::to_string(mesh.V.rows()));
  }
  // A map lists the faces of the mesh it was made for. Same vertex count but other faces is a
  // map of another mesh (a remesh, a different export of the same scan): using it would give
  // a folded or meaningless result that passes every per-point check.
  if (points.F.rows() > 0 && mesh.F.rows() > 0) {
    if (points.F.rows() != mesh.F.rows())
      return Status(ErrorCode::InvalidInput, path + ": has " + std::to_string(points.F.rows()) + " faces, mesh has " +
                                                 std::to_string(mesh.F.rows()) + " (a map of another mesh)");
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
      if (points.F.row(f) != mesh.F.row(f))
        return Status(ErrorCode::InvalidInput, path + ": face " + std::to_string(f) +
                                                   " differs from the mesh's (a map of another mesh)");
  }
  SphereMap map;
  map.S = std::move(points.V);
  for (Eigen::Index i = 0; i < map.S.rows(); ++i) {
    // parse_mesh has rejected NaN/Inf. The norm is only a test here (inf for finite points
    // near DBL_MAX * sqrt(3)); unit_vector normalises without overflow or underflow.
    const double norm = map.S.row(i).stableNorm();
    if (norm == 0) {
      return Status(ErrorCode::InvalidInput, path + ": point " + std::to_string(i) + " is zero (not on the sphere)");
    }
    if (!(std::abs(norm - 1) <= kUnitRoundoff)) {
      map.S.row(i) = detail::unit_vector(map.S.row(i).transpose()).transpose();
    }
  }
  if (file_extension(path) == "obj") SPHEREKIT_RETURN_IF_ERROR(parse_provenance(path, bytes, map.provenance));
  return map;
}

}  // namespace detail

Result<SphereMap> read_sphere_map(const std::string& path, const TriMesh& mesh) {
  SPHEREKIT_ASSIGN_OR_RETURN(std::string bytes, read_file(path));
  return detail::parse_sphere_map(path, bytes, mesh);
}

}  // namespace spherekit::formats
