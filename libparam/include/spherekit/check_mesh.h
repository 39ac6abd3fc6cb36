// Structural checks of an input mesh: every stage runs check_mesh() first and refuses
// what it cannot handle with a precise message.
#pragma once

#include <string>
#include <vector>

#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit {

/// Everything the stages need to know about a mesh's structure. Counts, not booleans,
/// so reports can say how bad a problem is.
struct MeshCheck {
  int vertices = 0;
  int faces = 0;
  int edges = 0;                   ///< undirected edges
  int unreferenced_vertices = 0;   ///< vertices used by no face
  int nonfinite_vertices = 0;      ///< vertices with a NaN or Inf coordinate
  int invalid_indices = 0;         ///< face indices outside [0, #V)
  int degenerate_faces = 0;        ///< faces repeating a vertex index (combinatorially degenerate)
  int zero_area_faces = 0;         ///< faces whose 3D area is 0 (collinear corners), relative to bbox
  int duplicate_faces = 0;         ///< faces with the same vertex set as an earlier face
  int boundary_edges = 0;          ///< edges with one incident face
  int nonmanifold_edges = 0;       ///< edges with more than two incident faces
  int orientation_conflicts = 0;   ///< manifold edges used twice in the same direction
  int nonmanifold_vertices = 0;    ///< vertices whose faces form more than one fan ("pinched")
  int boundary_loops = 0;
  int components = 0;              ///< connected components (over faces)
  int euler = 0;                   ///< V - E + F over referenced vertices
  int genus = -1;                  ///< (2 - euler - boundary_loops) / 2 per component; -1 if undefined
  bool orientable = true;
  double bbox_diag = 0;
  std::vector<int> nonmanifold_vertex_ids;  ///< first few offending vertices, for messages
  std::vector<int> nonmanifold_edge_ids;    ///< first few offending edges as vertex pairs (flattened)

  // Added detail for precise messages (-1 / empty when there is no such element). Lists
  // hold at most kMaxReportedIds entries, in increasing id order.
  std::vector<int> nonmanifold_vertex_fans;       ///< fan count of each nonmanifold_vertex_ids entry
  std::vector<int> nonmanifold_edge_face_counts;  ///< face count of each nonmanifold_edge_ids pair
  int first_nonfinite_vertex = -1;
  int first_invalid_face = -1;      ///< first face with an index outside [0, #V)
  int first_invalid_index = 0;      ///< the offending index of that face
  int first_degenerate_face = -1;
  int first_zero_area_face = -1;
  int first_duplicate_face = -1;    ///< first face repeating an earlier face's vertex set...
  int first_duplicate_of = -1;      ///< ...and that earlier face
  int first_unreferenced_vertex = -1;
  int first_conflict_from = -1;     ///< first edge used twice in the same direction,
  int first_conflict_to = -1;       ///< as the direction both faces use

  /// True if the mesh is one manifold, oriented, genus-0 component (boundary loops allowed)
  /// with finite coordinates and no degenerate faces: what the parameterizer accepts.
  bool genus0_ok() const;
};

/// At most this many ids are listed in MeshCheck's id vectors.
inline constexpr int kMaxReportedIds = 8;

/// A face is zero-area when |(b - a) x (c - a)| <= kZeroAreaRelTolerance * bbox_diag^2, i.e.
/// twice its area is below 1e-12 of the squared bounding-box diagonal: relative, so the
/// verdict does not depend on the mesh's units, and far below any face a real mesh (or a
/// float-precision file) can resolve. Zero-area faces are reported, never refused.
inline constexpr double kZeroAreaRelTolerance = 1e-12;

/// Computes the MeshCheck of a mesh. Never fails: invalid indices are counted, not followed.
///
/// Definitions (identical to shared/tools/meshcheck.py where that tool defines a count):
/// - Faces with an invalid index are counted in `invalid_indices` (once per bad index) and
///   otherwise ignored; faces repeating an index are `degenerate_faces` and take part only
///   in `components` and in the referenced-vertex set. All other counts use the remaining
///   ("usable") faces.
/// - `duplicate_faces`: usable faces whose vertex set equals an earlier usable face's.
///   Duplicates also make their edges non-manifold (three or more faces).
/// - `nonmanifold_vertices`: vertices whose corners form more than one fan, fans being
///   joined across two-face edges only. This counts pinched vertices (two cones touching)
///   and the endpoints of non-manifold edges.
/// - `boundary_loops`: with manifold, consistently oriented edges, the cycles of boundary
///   edges traced through each vertex's own fan (two loops touching at a pinched vertex
///   count as two); otherwise the connected components of the boundary-edge graph.
/// - `euler` = referenced vertices - edges + usable faces. `genus` = (2 - euler -
///   boundary_loops) / 2 when the mesh is one orientable component without non-manifold
///   edges or vertices (and the result is a non-negative integer), else -1.
/// - `bbox_diag`: diagonal of the bounding box of the referenced, finite vertices.
/// Cost: O(V + F) time and memory (about 30 ms for 270k faces).
MeshCheck check_mesh(const TriMesh& mesh);

/// InvalidInput with a one-line message naming the first problem that makes `check`
/// unacceptable for spherical parameterization (genus != 0, several components,
/// non-manifold, NaN, ...); Ok if genus0_ok(). `allow_boundary`: whether boundary loops
/// are acceptable (they are, for stages that fill holes).
///
/// Problems are tested in this order, so the message names the cause rather than a
/// consequence (a duplicate face also creates non-manifold edges): no faces, invalid
/// indices, NaN/Inf coordinates, degenerate faces, duplicate faces, non-manifold edges,
/// non-manifold vertices, several components, unreferenced vertices, non-orientable,
/// inconsistent orientation, genus != 0, boundary loops (only if !allow_boundary).
/// Unreferenced vertices are refused: a SphereMap gives every vertex a sphere point, and a
/// vertex used by no face has no place on the surface, so it could only be put somewhere
/// arbitrary. Remove them first (their positions carry no surface information).
/// Zero-area faces are not refused: they are valid topology; stages that divide by areas
/// handle them (see kZeroAreaRelTolerance).
Status require_genus0(const MeshCheck& check, bool allow_boundary = true);

/// Coordinates parameterization accepts: every |x| <= kMaxCoordinate and a bounding-box
/// diagonal >= kMinExtent. Beyond these, squared lengths, cross products and areas of the mesh
/// overflow or underflow in double precision (|x| = 1e300 makes every area inf, 1e-100 makes
/// it 0), so stretch and quality numbers come out NaN or 0 while everything else looks fine.
/// 1e50 leaves room for the 4th and higher powers of lengths the stretch computation forms.
inline constexpr double kMaxCoordinate = 1e50;
inline constexpr double kMinExtent = 1e-50;

/// InvalidInput if the mesh's coordinates are outside the range above (or all vertices
/// coincide); Ok otherwise (and for a mesh without vertices). Coordinates must be finite
/// (require_genus0 refuses others first).
Status require_supported_coordinates(const TriMesh& mesh);

/// What spherical parameterization accepts, as one verdict: require_genus0(check,
/// allow_boundary), then require_supported_coordinates(mesh). Every stage that maps a mesh
/// (parameterize_sphere, parameterize_sphere_constrained, parameterize_consistent) refuses
/// with it, and `spherekit check`, `param`, `convert`, `consistent` and `add` judge with it,
/// so a library user and the command line get the same verdict. `check` must be
/// check_mesh(mesh).
Status require_param_accepts(const TriMesh& mesh, const MeshCheck& check, bool allow_boundary = true);

/// Splits every non-manifold ("pinched") vertex into one vertex per face fan. New vertices
/// are appended at the end with the same position; `new_to_old` (if given) receives, for
/// each appended vertex, the vertex it was split from. Returns the number of splits.
///
/// Fans are those of MeshCheck::nonmanifold_vertices, so afterwards that count is 0. The
/// fan holding the vertex's first corner (lowest face index) keeps the original id; the
/// other fans get new ids in the order of their first corners (deterministic). A vertex on
/// a non-manifold edge is split too, which detaches the extra sheets along that edge.
/// Faces with invalid or repeated indices are left untouched. `new_to_old` is cleared
/// first; the return value equals its size (the number of appended vertices).
int repair_pinched_vertices(TriMesh& mesh, std::vector<int>* new_to_old = nullptr);

/// Drops the vertices no face uses (MeshCheck::unreferenced_vertices), keeping the order of the
/// others; faces keep their order and are renumbered. Returns the number dropped. `old_to_new`
/// (if given) receives, per vertex of the mesh as passed, its new index or -1 if it was dropped:
/// anything indexing the old vertices (landmark files) must be remapped through it. A mesh
/// with a face index outside [0, #V) is left unchanged (returns 0, identity map).
/// O(V + F). Dropping them loses nothing of the surface: a vertex no face uses has no place on
/// it (which is why require_genus0 refuses them).
int remove_unreferenced_vertices(TriMesh& mesh, std::vector<int>* old_to_new = nullptr);

}  // namespace spherekit
