// Reading a mesh with its structural check, and the verdict whether param accepts it, as
// `check`, `param` and every job use them.
#pragma once

#include <string>

#include "spherekit/check_mesh.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit::pipeline {

/// A mesh as read from disk, with its structural check.
struct LoadedMesh {
  std::string path;
  TriMesh mesh;
  MeshCheck check;
  formats::ReadInfo info;
  int split_vertices = 0;  ///< vertices added by repair_pinched_vertices (repair = true)
  double read_seconds = 0, check_seconds = 0;
};

/// Reads and checks a mesh without judging it (for `check`). The error message starts
/// with the file path.
Result<LoadedMesh> load_mesh(const std::string& path);

/// What repair_mesh did.
struct MeshRepair {
  int removed_unreferenced_vertices = 0;  ///< remove_unreferenced_vertices
  int split_vertices = 0;                 ///< copies added by repair_pinched_vertices
  /// A kept vertex got another number (a vertex dropped at the end changes none): landmark
  /// files of the input no longer fit.
  bool renumbered = false;
};

/// `check --repair`: drops vertices no face uses and splits pinched ones, the only repairs
/// that leave the surface as it is (anything else would change it silently), then checks the
/// mesh again.
MeshRepair repair_mesh(LoadedMesh& mesh);

/// What `param` accepts: the library's one verdict (require_param_accepts, check_mesh.h) with
/// the message starting with the file path.
Status param_verdict(const LoadedMesh& mesh, bool allow_boundary);

/// Reads a mesh, optionally splits pinched vertices, checks it and refuses anything the
/// parameterizer cannot handle (param_verdict). `allow_boundary`: holes are acceptable.
/// The error message starts with the file path.
Result<LoadedMesh> load_mesh_checked(const std::string& path, bool allow_boundary, bool repair);

}  // namespace spherekit::pipeline
