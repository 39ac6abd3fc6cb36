// Splitting non-manifold ("pinched") vertices: each face fan around a vertex gets its own
// copy of the vertex, the repair the authors' tools needed for cow.obj (REFERENCE.md).
// Fans are those of check_mesh (corners joined across two-face edges), so after the split
// check_mesh reports no non-manifold vertex. O(V + F).
#include <vector>

#include "detail/check_topology.h"
#include "spherekit/check_mesh.h"

namespace spherekit {

int repair_pinched_vertices(TriMesh& mesh, std::vector<int>* new_to_old) {
  if (new_to_old) new_to_old->clear();
  const detail::MeshTopology topo = detail::build_topology(mesh);
  const std::vector<int> fan = detail::corner_fans(mesh, topo);
  const int nv = static_cast<int>(mesh.V.rows());

  // Corners are visited in increasing order, so the fan holding a vertex's first corner
  // is met first and keeps the vertex; every later new fan gets the next new id. A fan's
  // representative is one of its corners, so a per-corner table maps fans to vertex ids.
  std::vector<int> fan_vertex(fan.size(), -1);
  std::vector<char> vertex_taken(static_cast<size_t>(nv), 0);
  std::vector<int> origin;  // for each appended vertex, the vertex it was split from
  for (int c = 0; c < static_cast<int>(fan.size()); ++c) {
    if (fan[c] < 0) continue;  // unusable face: untouched
    const int root = fan[c];
    if (fan_vertex[root] < 0) {
      const int v = mesh.F(c / 3, c % 3);
      if (!vertex_taken[v]) {
        vertex_taken[v] = 1;
        fan_vertex[root] = v;
      } else {
        fan_vertex[root] = nv + static_cast<int>(origin.size());
        origin.push_back(v);
      }
    }
    mesh.F(c / 3, c % 3) = fan_vertex[root];
  }
  if (!origin.empty()) {
    const int added = static_cast<int>(origin.size());
    mesh.V.conservativeResize(nv + added, 3);
    for (int i = 0; i < added; ++i) mesh.V.row(nv + i) = mesh.V.row(origin[i]);
  }
  if (new_to_old) *new_to_old = origin;
  return static_cast<int>(origin.size());
}

}  // namespace spherekit
