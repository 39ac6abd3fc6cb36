// Internal: the edge/fan/boundary structure that check_mesh, repair_pinched_vertices and
// fill_holes share. Built from plain F arrays in O(F) (bucketing by vertex, no hashing, no
// global sort) so a 270k-face mesh takes a few tens of milliseconds.
//
// Conventions:
//   half-edge h = 3*f + k runs from F(f,k) to F(f,(k+1)%3); corner c = 3*f + k is the
//   corner of face f at F(f,k), so half-edge h starts at corner h.
//   Only "usable" faces (all indices valid, no repeated index) enter the structure; the
//   others are counted by check_mesh and otherwise ignored.
#pragma once

#include <cstdint>
#include <vector>

#include "spherekit/mesh.h"

namespace spherekit::detail {

struct MeshTopology {
  int num_vertices = 0;
  int num_faces = 0;
  std::vector<char> usable;      ///< per face: indices valid and distinct
  int num_edges = 0;             ///< undirected edges of usable faces
  std::vector<int> edge_start;   ///< CSR: half-edges of edge e are edge_he[edge_start[e] .. edge_start[e+1])
  std::vector<int> edge_he;
  std::vector<int> twin;         ///< per half-edge: the other half-edge of a two-face edge, else -1
                                 ///< (-1 also on boundary, non-manifold edges and unusable faces)
  std::vector<int> he_edge;      ///< per half-edge: its edge id, -1 for unusable faces

  int edge_size(int e) const { return edge_start[e + 1] - edge_start[e]; }
};

/// Start and end vertex of half-edge h.
inline int he_from(const TriMesh& m, int h) { return m.F(h / 3, h % 3); }
inline int he_to(const TriMesh& m, int h) { return m.F(h / 3, (h % 3 + 1) % 3); }
/// Next half-edge in the same face.
inline int he_next(int h) { return h - h % 3 + (h % 3 + 1) % 3; }

/// Builds the edge table of the usable faces.
MeshTopology build_topology(const TriMesh& mesh);

/// Labels every corner of a usable face with its fan: corners at the same vertex are in
/// one fan when their faces are joined, around that vertex, through two-face edges.
/// Returns per corner a fan id (a representative corner), -1 for unusable faces.
std::vector<int> corner_fans(const TriMesh& mesh, const MeshTopology& topo);

/// Per vertex the number of distinct fans among its corners (0 for unreferenced vertices).
std::vector<int> fans_per_vertex(const TriMesh& mesh, const std::vector<int>& fan_of_corner);

/// Boundary loops as cycles of boundary half-edges, each half-edge oriented as in its face
/// (so the surface is on the left). Requires no non-manifold edges and consistent
/// orientation; the successor of a boundary half-edge a->b is found by walking around b
/// through its fan, so a vertex where two boundary loops touch is handled: each loop
/// continues within its own fan. Returns the loops as half-edge ids, ordered by their
/// smallest half-edge; `ok` is false if the walk ever fails (then the result is empty).
std::vector<std::vector<int>> trace_boundary_loops(const TriMesh& mesh, const MeshTopology& topo, bool* ok);

}  // namespace spherekit::detail
