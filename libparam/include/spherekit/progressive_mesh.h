// Progressive mesh by half-edge collapses (Hoppe 1996), vertices keep their original
// positions, ordered by an n-D quadric error (Garland & Heckbert 1998), down to a
// tetrahedron. The same simplifier serves the unconstrained map (d = 3) and the consistent
// method's step 5 (d = 3n, Asirvatham et al. 2005 §3).
#pragma once

#include <array>
#include <vector>

#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit {

/// One half-edge collapse vt -> vs, recorded so that the vertex split can replay it exactly.
struct HalfEdgeCollapse {
  int vt = -1;                   ///< the vertex removed (re-inserted by the split)
  int vs = -1;                   ///< the vertex it collapses into (keeps its position)
  int vl = -1, vr = -1;          ///< third vertices of the two faces removed: (vs,vt,vl)...
  std::array<int, 2> removed{{-1, -1}};  ///< face ids removed by the collapse
  int moved_begin = 0, moved_end = 0;    ///< range in ProgressiveMesh::moved_faces
};

/// A progressive mesh: the full mesh, the sequence of collapses (simplification order) and
/// enough bookkeeping to replay it backwards as vertex splits.
struct ProgressiveMesh {
  int num_vertices = 0;
  RowMat3i F;                              ///< full-resolution faces (input order)
  std::vector<HalfEdgeCollapse> collapses; ///< in simplification order
  std::vector<int> moved_faces;            ///< faces whose vt became vs, per collapse range
  /// Face corners at the moment each face was removed (flattened 3 per removed face, in
  /// collapse order, two faces per collapse): the split restores them exactly.
  std::vector<std::array<int, 3>> removed_corners;
  std::vector<int> base_vertices;          ///< vertices alive at the base (4 for a tetrahedron)
  std::vector<int> base_faces;             ///< faces alive at the base
  int forced_collapses = 0;                ///< collapses that had to ignore the geometric checks
};

struct ProgressiveMeshOptions {
  /// Weight of each face's quadric (e.g. small for faces that close holes); empty = 1.
  std::vector<double> face_weights;
  /// Vertices that must never be removed (feature vertices); empty = none.
  std::vector<char> keep_vertices;
  /// Constrained simplification (Asirvatham et al. 2005 §4): the edges of a path network.
  /// A vertex on exactly two of them (a path's interior vertex) may only collapse along one
  /// of them into its path neighbour; a vertex on one or more than two never moves (give it
  /// in keep_vertices too); other vertices collapse freely. The path edges are carried
  /// through the collapses, so each path shrinks to the single edge between its features.
  std::vector<std::array<int, 2>> constraint_edges;
  /// Stop when this many vertices remain (4 = tetrahedron; larger for constrained bases).
  int target_vertices = 4;
  /// Relative weight of the squared edge length added to the quadric cost; it breaks the
  /// ties QEM leaves in flat regions in favour of short edges (better-shaped levels).
  double edge_length_weight = 0.01;
  /// Weight of the vertex normals in the quadric (0 = positions only), in units of the
  /// coordinates: with positions normalized to a unit bounding-box diagonal, 0.02 is
  /// MeshSimplify's (Hoppe 1999) normal term. Keeps thin limbs to coarse levels.
  double normal_weight = 0;
  /// Memoryless quadrics (Lindstrom & Turk 1998): a collapse costs the distances to the
  /// planes of the faces around it at the current level, instead of quadrics accumulated
  /// from the original faces.
  bool memoryless = false;
  /// Each model's squared distance to its own face plane, weighted by the face's area in
  /// that model, summed over the models: the error each model's level shows. The default
  /// measures the distance to the face's 2-plane in R^d weighted by the area summed over the
  /// models (the consistent method's step 5, Asirvatham et al. 2005 §3), which also charges
  /// the models' tangential disagreement and grows as n^2 for n equal models, like the
  /// edge-length tie-break; here the plane term grows as n, so the tie-break weighs n times
  /// more. Measured on levels of detail (four TOSCA cats, level 3 of 78 vertices): 31.7-36.2
  /// dB against 24.7-29.6 (paws 12-23% of the diagonal away); neither half alone does it
  /// (model planes weighted as the 2-plane: 24.0-27.1; the 2-plane with a 4x tie-break:
  /// 22.8-25.2). Identical to the default for one model (d = 3). Requires normal_weight = 0.
  bool model_planes = false;
  /// Fold-over check: a face that is degenerate before the collapse (zero area up to
  /// rounding) has no orientation to keep, so it does not veto the collapse. Geometry images
  /// of meshes with holes hold the hole texels on the rim (zero-area faces); without this
  /// every collapse touching them was illegal, the simplifier stalled and then forced
  /// fold-overs for the rest (bunny's coarsest adaptive LOD: 22.7 dB). Off by default: the
  /// parameterization's simplification stays as it was.
  bool degenerate_faces_free = false;
  /// Parallel fine levels (memoryless quadrics, no constraint edges or kept vertices): with
  /// block_vertices > 0 and a mesh of at least 1.5 x that many vertices, the mesh is first
  /// cut into spatial blocks of about this many vertices (two below 2 x); each block is
  /// simplified on its own (blocks in parallel) by the same greedy, its vertices next to
  /// another block held, and one cost cut for all blocks keeps (1 - block_fraction) of their
  /// other vertices' collapses in all; rounds repeat while two blocks remain, then the greedy
  /// goes on over the whole mesh. The blocks depend on the mesh only, so the result does not
  /// depend on `threads`.
  /// 0 (default): one greedy over the whole mesh.
  int block_vertices = 0;
  double block_fraction = 0.2;
  int threads = 1;  ///< threads for the blocks (0 = all cores)
};

/// Builds the progressive mesh of a closed, manifold, genus-0 triangle mesh whose vertex
/// coordinates P are #V by d (d = 3 for one model, 3n for n models; each consecutive block
/// of 3 columns is one model, used for fold-over checks).
/// Errors: InvalidInput (sizes), SolverFailed (could not reach the target, e.g. not genus 0),
/// Cancelled.
/// The collapses of a progressive mesh replayed forwards, as levels of detail read them:
/// which vertex each input vertex has become and which input faces are still alive.
class CollapseReplay {
 public:
  explicit CollapseReplay(const ProgressiveMesh& pm);
  /// Applies the collapses up to (not including) `count` (at most all of them).
  void advance_to(std::size_t count);
  /// The vertex that input vertex v has become.
  int find(int v) const;
  bool alive(int face) const { return alive_[static_cast<std::size_t>(face)] != 0; }

 private:
  const ProgressiveMesh* pm_;
  std::vector<int> parent_;
  std::vector<char> alive_;
  std::size_t done_ = 0;
};

Result<ProgressiveMesh> build_progressive_mesh(const RowMatXd& P, const RowMat3i& F,
                                               const ProgressiveMeshOptions& options = {},
                                               const ProgressFn& progress = {});

}  // namespace spherekit
