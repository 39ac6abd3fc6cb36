// The path network of a constrained spherical parameterization (Asirvatham et al. 2005 §4):
// a "triangulation" of the feature vertices embedded twice, as non-crossing great-circle arcs
// between the target points on the sphere and as non-crossing vertex paths on the mesh, with
// identical combinatorics. Internal to libparam.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::detail {

struct NetworkOptions {
  /// Cost factor of steps through edge midpoints (Steiner vertices, Kraevoy & Sheffer 2003):
  /// they let paths squeeze between close features but are used only where they pay off.
  double steiner_penalty = 2.0;
  bool steiner = true;  ///< allow Steiner vertices at all
  /// Arcs making angles below this with an arc already at one of their ends are deferred
  /// (§4.1: the winding of skinny spherical triangles is unreliable).
  double min_angle_deg = 10.0;
  /// Share of the features counted as extremities (largest mean distance to their nearest
  /// features), which the spanning tree links first (§4.1).
  double extremity_fraction = 0.25;
  bool sidedness = true;   ///< defer paths that leave nearby features on the wrong side (§4.1)
  bool unswirl = true;     ///< the unswirl operator (§4.1)
  bool edge_flips = true;  ///< replace a path by the shorter other diagonal of its quad (§4)
  /// A path whose length exceeds this multiple of its end points' geodesic distance is
  /// "long" (a swirl symptom, §4.1).
  double long_path_ratio = 1.6;
  /// Rank candidate paths by the geometric mean of their surface length and their arc's
  /// angle instead of the surface length alone (path_network.cpp, rank_cost).
  bool arc_ranking = true;
};

/// A network edge: feature a to feature b (indices into the feature list), embedded as the
/// mesh vertex path `verts` (verts.front() is a's vertex, verts.back() is b's).
struct NetworkPath {
  int a = -1, b = -1;
  std::vector<int> verts;
  double length = 0;    ///< surface length of the path
  double geodesic = 0;  ///< unrestricted shortest-path distance between a and b on the mesh
};

struct PathNetwork {
  /// The mesh the paths live on: the input vertices first, then the Steiner vertices added
  /// by splitting edges at their midpoints (in creation order); faces are the input's with
  /// the splits applied.
  std::vector<Eigen::Vector3d> X;
  std::vector<std::array<int, 3>> F;
  std::vector<int> face_origin;  ///< input face each face came from
  std::vector<std::array<int, 2>> steiner_parent;  ///< per Steiner vertex: the edge it split
  /// How each split changed the faces, to undo the splits in reverse order: face f[i] had
  /// corners old[i] and face g[i] was appended.
  struct Split {
    std::array<int, 2> f{{-1, -1}}, g{{-1, -1}};
    std::array<std::array<int, 3>, 2> old{};
  };
  std::vector<Split> splits;  ///< per Steiner vertex, in creation order
  std::vector<int> feature_vertex;  ///< per feature: its vertex
  std::vector<NetworkPath> paths;   ///< 3k - 6 edges once complete
  std::vector<std::array<int, 3>> triangles;  ///< feature triples, ccw on the sphere and the mesh
  // Statistics for reports.
  double total_length = 0;
  double max_ratio = 0;         ///< max over paths of length / geodesic
  int swirls_fixed = 0;         ///< unswirl operations that were kept
  int edge_flips = 0;           ///< paths replaced by the other diagonal
  int deferred = 0;             ///< candidate paths put at the end of the queue by a heuristic
  int sidedness_deferred = 0;
};

/// Builds the network on the closed, consistently oriented mesh (V, F) for the feature
/// vertices and their unit target points (at least 4 features, targets not contained in a
/// closed hemisphere). Errors: InvalidInput (features not distinct...), SolverFailed (the
/// greedy insertion could not complete the triangulation), Cancelled.
Result<PathNetwork> build_path_network(const RowMat3d& V, const RowMat3i& F, const std::vector<int>& feature_vertex,
                                       const std::vector<Eigen::Vector3d>& targets, const NetworkOptions& options,
                                       const ProgressFn& progress);

/// True if the points are not all contained in one closed hemisphere with some margin (the
/// origin is inside their convex hull), the condition for a triangulation of the sphere whose
/// spherical triangles are all smaller than a hemisphere.
bool targets_surround_origin(const std::vector<Eigen::Vector3d>& targets, double margin = 0.05);

}  // namespace spherekit::detail
