// A map from mesh vertices to the unit sphere, plus where it came from.
#pragma once

#include <cstdint>
#include <string>

#include "spherekit/mesh.h"

namespace spherekit {

/// What produced a sphere map: recorded in reports and output headers.
struct Provenance {
  std::string library_version;  ///< spherekit::kVersion at creation
  std::string method;           ///< e.g. "unconstrained", "constrained"
  std::string options_digest;   ///< hex digest of the shape-defining options
  std::uint64_t seed = 0;       ///< random seed used
};

/// A map from mesh vertices to the unit sphere.
struct SphereMap {
  RowMat3d S;             ///< #V by 3 unit vectors, same vertex order as TriMesh::V
  Provenance provenance;  ///< library version, option digest, seed
};

}  // namespace spherekit
