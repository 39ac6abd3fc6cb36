// Constrained spherical parameterization (Asirvatham, Praun, Hoppe 2005 §4): a bijective
// map of a genus-0 mesh onto the unit sphere in which given feature vertices land exactly on
// given sphere points, with low stretch. The building block of consistent parameterization.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/sphere_map.h"
#include "spherekit/sphere_param.h"
#include "spherekit/status.h"

namespace spherekit {

struct ConstrainedParamOptions {
  /// Stretch optimizer settings (shared with the unconstrained stage; align_rotation is
  /// ignored: the targets fix the orientation); the collection stages' anti-cruft weight.
  SphereParamOptions sphere = collection_sphere_options();
  // Path network (§4, §4.1). Shape-defining.
  double steiner_penalty = 2.0;     ///< cost factor of paths through edge midpoints
  double min_angle_deg = 10.0;      ///< arcs making smaller angles are inserted last
  double extremity_fraction = 0.25; ///< share of features linked first as extremities
  bool sidedness = true;            ///< defer paths leaving nearby features on the wrong side
  bool unswirl = true;              ///< detect and re-insert swirling paths
  bool edge_flips = true;           ///< replace paths by the shorter diagonal of their quad
  /// Rank candidate paths by the geometric mean of their surface length and their arc's
  /// angle between the targets, not by surface length alone (detail/path_network.h).
  bool arc_ranking = true;
  /// Simplify and optimize as the unconstrained stage does (sphere_param.cpp: quadrics with
  /// the vertex normals, memoryless; edge-frame anti-cruft; the final pass on the measured
  /// energy) instead of with the collection stages' settings. Thin limbs then keep their
  /// share of the sphere at the coarse levels. Off by default: with the collection's
  /// settings the correspondence comes out better where both are efficient (measured in
  /// constrained_param_or_retry's comment); the collections use it as their retry.
  bool as_unconstrained = false;
};

/// The path network as built, for reports and inspection (`--dump-network`).
struct FeatureNetworkReport {
  int paths = 0;                  ///< 3k - 6 for k features (k counts auxiliary ones too)
  double total_length = 0;        ///< summed surface length of the paths (input units)
  double max_ratio = 0;           ///< max over paths of length / shortest-path distance
  int swirls_fixed = 0;           ///< unswirl operations kept
  int edge_flips = 0;             ///< paths replaced by the other diagonal of their quad
  int deferred = 0;               ///< candidates put at the end of the queue by a heuristic
  int steiner_vertices = 0;       ///< edges split at their midpoint to route paths
  int auxiliary_features = 0;     ///< extra features added (fewer than 4, or one-sided targets)
  int attempts = 1;               ///< network variants tried (Steiner cost varied on failure)
  int flips_after_steiner_removal = 0;  ///< input faces flipped when Steiner vertices were dropped (then untangled)
  /// Dense feature sets (more than 32): the network links a well-spread subset of 24 and the
  /// other features are carried onto their targets by a bijective flow of the sphere; how
  /// many, in how many steps (0 and 0 for sparse sets).
  int warped_features = 0;
  int warp_steps = 0;
  std::vector<std::vector<Eigen::Vector3d>> polylines;  ///< each path on the surface (input coordinates)
  std::vector<std::array<int, 2>> arcs;  ///< each path's features (indices; auxiliary ones after the given)
  std::vector<Eigen::Vector3d> arc_targets;  ///< sphere points of all features, given then auxiliary
};

struct ConstrainedParamTimes {
  double check = 0, network = 0, simplify = 0, refine = 0, total = 0;
};

struct ConstrainedParamResult {
  SphereMap map;                 ///< one unit vector per input vertex
  int flipped_faces = 0;         ///< by the exact predicate: 0 for a bijection
  double efficiency = 0;         ///< stretch efficiency over the input's faces (metrics.h)
  double l2_stretch = 0, linf_stretch = 0;
  double winding = 0;
  double max_feature_angle = 0;  ///< max angle (radians) between a feature's image and its target
  int holes_filled = 0;
  FeatureNetworkReport network;
  ConstrainedParamTimes times;
  /// constrained_param_or_retry(): the map was made twice (the first kept too little of the
  /// unconstrained efficiency), with the efficiency of the first attempt; whether the map
  /// returned is the second (made with as_unconstrained).
  bool efficiency_retried = false;
  double first_efficiency = 0;
  bool as_unconstrained = false;
};

/// Maps a genus-0 mesh (holes allowed) onto the unit sphere so that vertex
/// feature_vertices[i] lands on targets[i].
/// 0 features: the unconstrained map. 1 feature: the unconstrained map rotated onto the
/// target. 2-3 features, or targets all on one side of the sphere: auxiliary features are
/// added so that the features triangulate the sphere: each at the point of a fixed lattice
/// farthest from the targets so far (so meshes mapped to the same targets get the same
/// auxiliary targets, and networks of the same layout), on the vertex the rotated
/// unconstrained map puts nearest to it; reported in network.auxiliary_features.
/// SolverFailed also when a stretch pass does not converge (more than 100 vertex moves per
/// vertex; normal maps need at most about 31).
/// @return the map, or InvalidArgument (sizes, targets not unit vectors), InvalidInput (mesh
///         not genus 0, two features on one vertex, targets closer than 1e-7 rad),
///         SolverFailed (the path network could not be completed), Cancelled.
/// Deterministic for any thread count.
Result<ConstrainedParamResult> parameterize_sphere_constrained(const TriMesh& mesh,
                                                               const std::vector<int>& feature_vertices,
                                                               const std::vector<Eigen::Vector3d>& targets,
                                                               const ConstrainedParamOptions& options = {},
                                                               const ProgressFn& progress = {});

/// The stretch efficiency of the mesh's own unconstrained map made with `options.sphere` (no
/// rotation): what constrained_param_or_retry() compares against (collections, `add`).
Result<double> own_unconstrained_efficiency(const TriMesh& mesh, const ConstrainedParamOptions& options,
                                            const ProgressFn& progress = {});

/// parameterize_sphere_constrained(), made again with ConstrainedParamOptions::as_unconstrained
/// when its efficiency is below retry_below x unconstrained_efficiency (the mesh's
/// unconstrained map's), keeping the more efficient map (the first on a tie or when the
/// retry fails). retry_below <= 0 or unconstrained_efficiency <= 0: no retry. The
/// collection stages (steps 2 and 6, `add`) use it so that no member's map keeps far less of
/// its own stretch efficiency than the constraints force. Deterministic for any thread count.
Result<ConstrainedParamResult> constrained_param_or_retry(const TriMesh& mesh, const std::vector<int>& feature_vertices,
                                                          const std::vector<Eigen::Vector3d>& targets,
                                                          const ConstrainedParamOptions& options,
                                                          double unconstrained_efficiency, double retry_below,
                                                          const ProgressFn& progress = {});

}  // namespace spherekit
