// Shared by the libFuzzer harnesses: the reader contracts every successful read must meet.
// A violation is a finding like a crash: the harness aborts (__builtin_trap), so libFuzzer
// saves the input. Readers get the bytes in memory (formats/src/*_codecs.h), never a file.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "mesh_codecs.h"
#include "spherekit/formats/mesh_io.h"

namespace spherekit::fuzz {

/// Traps unless `condition` holds (a reader broke its documented contract).
inline void require(bool condition) {
  if (!condition) __builtin_trap();
}

inline std::string_view bytes_of(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// The error contract: a non-Ok code and a non-empty, one-line message naming the file.
inline void require_good_error(const Status& status, const std::string& path) {
  require(!status.ok());
  require(!status.message().empty());
  require(status.message().find('\n') == std::string::npos);
  require(status.message().rfind(path, 0) == 0);
}

/// Parses a mesh file of the format `path`'s extension names and checks read_mesh's contract:
/// on success at least one face, every index in range and every coordinate finite; the mesh
/// then survives an OBJ and a binary PLY round trip bit for bit (what the writers promise).
inline void fuzz_mesh(const std::string& path, const std::uint8_t* data, std::size_t size) {
  // Vary the polygon policy with the input, so all three paths of MeshBuilder are reached.
  formats::ReadOptions options;
  options.polygons = static_cast<formats::PolygonPolicy>(size % 3);
  formats::ReadInfo info;
  Result<TriMesh> mesh = formats::detail::parse_mesh(path, bytes_of(data, size), options, &info);
  if (!mesh.ok()) {
    require_good_error(mesh.status(), path);
    return;
  }
  const TriMesh& m = mesh.value();
  require(m.F.rows() > 0);
  require(m.V.allFinite());
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) require(m.F(f, k) >= 0 && m.F(f, k) < m.V.rows());
  }
  // Every triangle names its source face; sources are non-decreasing and each face of n
  // corners gives n - 2 triangles, so the counts add up.
  require(info.face_polygon.size() == static_cast<std::size_t>(m.F.rows()));
  for (std::size_t t = 0; t < info.face_polygon.size(); ++t) {
    require(info.face_polygon[t] >= 0 && info.face_polygon[t] < info.faces.faces);
    require(t == 0 || info.face_polygon[t] >= info.face_polygon[t - 1]);
  }
  require(info.faces.faces == info.faces.triangles + info.faces.quads + info.faces.ngons);
  for (const char* ext : {"obj", "ply"}) {
    const std::string copy = std::string("round_trip.") + ext;
    const std::string text =
        ext[0] == 'o' ? formats::detail::format_obj(m, 17, "") : formats::detail::format_ply(m, true, 17);
    Result<TriMesh> back = formats::detail::parse_mesh(copy, text, formats::ReadOptions{}, nullptr);
    require(back.ok());
    require(back->V.rows() == m.V.rows() && back->F == m.F);
    for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
      for (int k = 0; k < 3; ++k) {
        // Bitwise, except that -0.0 and +0.0 are the same coordinate.
        require(back->V(i, k) == m.V(i, k));
      }
    }
  }
}

}  // namespace spherekit::fuzz
