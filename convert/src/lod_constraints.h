// Simplifier constraints shared by the two level-of-detail modes (adaptive_lods.cpp,
// original_lods.cpp). Internal to spherekit::convert.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "spherekit/mesh.h"

namespace spherekit::convert::detail {

/// The rim between the faces that close holes (`hole_faces[f]` != 0) and the others, as
/// simplifier path edges: the edges whose two faces are on different sides. Merged into
/// `edges`, which ends sorted and unique.
void add_rim_edges(const RowMat3i& F, const std::vector<std::uint8_t>& hole_faces,
                   std::vector<std::array<int, 2>>& edges);

}  // namespace spherekit::convert::detail
