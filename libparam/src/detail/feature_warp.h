// Dense feature sets in the constrained stage (issue 19; the paper promises that the method
// "works well with either sparse or dense sets of constraints", abstract). Internal to libparam.
//
// Why: with many features on a coarse mesh (64 per 5k-vertex FAUST body) the path network
// runs paths side by side, so it needs well over a thousand Steiner vertices, and merging them
// back leaves folds next to fixed features that no local untangling repairs (measured: every
// network variant fails). So the network triangulates a well-spread subset of the features
// (the sparse case, which works), and the other features are then carried onto their targets
// by a smooth flow of the sphere, checked with the exact predicate at every step.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::detail {

/// Above this many features the constrained stage routes its path network through a subset.
constexpr int kDenseFeatureThreshold = 32;
/// Size of that subset: the first that works of these.
constexpr int kDenseNetworkSizes[] = {24, 16, 32};
constexpr int kDenseNetworkFeatures = kDenseNetworkSizes[0];

/// `count` indices of well-spread targets: farthest-point samples on the sphere (angles),
/// starting with target 0, ties to the lower index. Sorted ascending.
std::vector<int> spread_subset(const std::vector<Eigen::Vector3d>& targets, int count);

struct WarpStats {
  int steps = 0;     ///< accepted flow steps
  int rejected = 0;  ///< steps halved because a face flipped
  int reshaped = 0;  ///< slivers reshaped (untangle_patch) because they flipped at any step
};

/// Moves the map S (a bijection of the mesh with faces F onto the sphere: 0 flipped faces)
/// so that vertex fv[j] lands exactly on targets[j] for every j, by a flow of the sphere: each
/// step moves every feature a fraction of the way along its great arc and displaces all
/// vertices by the compactly supported radial-basis interpolant of the features' displacements (features
/// already on target do not move). A step that flips a face (exact predicate) is halved.
/// A face that flips however small the step (a sliver wider than the field's support) is
/// reshaped with untangle_patch against its shape in the mesh X, features fixed.
/// On success S has 0 flipped faces and every feature exactly on its target; otherwise
/// SolverFailed and S unchanged. Deterministic (one thread).
Status warp_features_to_targets(const RowMat3d& X, const RowMat3i& F, const std::vector<int>& fv,
                                const std::vector<Eigen::Vector3d>& targets, const ProgressFn& progress, RowMat3d* S,
                                WarpStats* stats = nullptr);

}  // namespace spherekit::detail
