// Undoing edge-midpoint splits (Steiner vertices) of the path network builder's mesh.
//
// The builder tries repairs (unswirl, edge flips) on a copy of its network state and rolls
// back when they do not pay off. The mesh must be rolled back with it: a discarded trial may
// have split an edge of a path it had removed (removed paths do not block the search), and
// after the rollback that path would step along an edge the mesh no longer has, which then
// neither blocks later searches nor survives the constrained simplification (a path vertex
// whose path neighbour is not a mesh neighbour can never be collapsed, so the simplification
// gets stuck above the feature triangulation). Kept Steiner vertices of discarded trials
// also pile up: each trial then searches a finer mesh and splits more (tens of thousands of
// Steiner vertices on a mesh of a few thousand vertices with dense features). Internal to
// libparam.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

#include "detail/path_network.h"

namespace spherekit::detail {

/// The builder's growing mesh: the input vertices first, then one Steiner vertex per split.
struct SplitMeshRefs {
  std::vector<Eigen::Vector3d>* X;
  std::vector<std::array<int, 3>>* F;
  std::vector<std::vector<int>>* vf;  ///< per vertex: incident faces (order not preserved)
  std::vector<int>* face_origin;
  std::vector<std::array<int, 2>>* steiner_parent;
  std::vector<PathNetwork::Split>* splits;
};

/// Undoes the splits after the first `keep`, newest first, restoring the faces each split
/// changed and dropping the faces and the vertex it added. Split i must have added faces
/// g[0], g[1] at the end of F and vertex X.size() - splits.size() + i (so undoing newest
/// first always pops the last faces and vertex). Cost: O(sum of the touched valences).
inline void undo_splits(const SplitMeshRefs& m, std::size_t keep) {
  auto& F = *m.F;
  auto& vf = *m.vf;
  auto drop = [&](int v, int f) {
    auto& l = vf[static_cast<std::size_t>(v)];
    auto it = std::find(l.begin(), l.end(), f);
    if (it != l.end()) l.erase(it);
  };
  while (m.splits->size() > keep) {
    const PathNetwork::Split& rec = m.splits->back();
    for (int slot = 1; slot >= 0; --slot) {
      const int f = rec.f[static_cast<std::size_t>(slot)], g = rec.g[static_cast<std::size_t>(slot)];
      if (f < 0) continue;
      for (int v : F[static_cast<std::size_t>(g)]) drop(v, g);
      for (int v : F[static_cast<std::size_t>(f)]) drop(v, f);
      F[static_cast<std::size_t>(f)] = rec.old[static_cast<std::size_t>(slot)];
      for (int v : F[static_cast<std::size_t>(f)]) vf[static_cast<std::size_t>(v)].push_back(f);
      if (g == static_cast<int>(F.size()) - 1) {
        F.pop_back();
        m.face_origin->pop_back();
      }
    }
    vf.pop_back();
    m.X->pop_back();
    m.steiner_parent->pop_back();
    m.splits->pop_back();
  }
}

}  // namespace spherekit::detail
