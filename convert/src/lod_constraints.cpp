// The rim constraint of the level-of-detail simplifiers (see lod_constraints.h).
#include "lod_constraints.h"

#include <algorithm>

namespace spherekit::convert::detail {

void add_rim_edges(const RowMat3i& F, const std::vector<std::uint8_t>& hole_faces,
                   std::vector<std::array<int, 2>>& edges) {
  std::vector<std::array<int, 3>> half;  // (min, max, side) per face edge
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      half.push_back({std::min(a, b), std::max(a, b), hole_faces[static_cast<std::size_t>(f)] ? 1 : 0});
    }
  std::sort(half.begin(), half.end());
  for (std::size_t i = 0; i + 1 < half.size(); ++i)
    if (half[i][0] == half[i + 1][0] && half[i][1] == half[i + 1][1] && half[i][2] != half[i + 1][2])
      edges.push_back({half[i][0], half[i][1]});
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
}

}  // namespace spherekit::convert::detail
