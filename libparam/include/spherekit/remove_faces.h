// Taking faces out of a mesh, and with them the vertices no remaining face uses.
#pragma once

#include <cstdint>
#include <vector>

#include "spherekit/mesh.h"

namespace spherekit {

/// `mesh` without the faces flagged 1 in `drop` (one flag per face) and without the vertices
/// no remaining face uses; the remaining vertices and faces keep their order. `new_index`
/// (optional) gets, per vertex of `mesh`, its index in the result or -1 if it was removed.
/// Flags of the wrong count, or a face index out of range, give `mesh` unchanged (and the
/// identity in `new_index`).
TriMesh remove_faces(const TriMesh& mesh, const std::vector<std::uint8_t>& drop,
                     std::vector<int>* new_index = nullptr);

}  // namespace spherekit
