// Invariants every sphere map must satisfy, as Catch2 assertions shared by the tests.
#pragma once

#include "spherekit/mesh.h"

namespace spherekit::test {

/// Unit vectors, every face positively oriented by the exact predicate, winding number +1
/// for closed meshes.
void require_valid_map(const TriMesh& mesh, const RowMat3d& S);

}  // namespace spherekit::test
