// Dense feature sets in the constrained stage (issue 19; the paper promises that the method
// "works well with either sparse or dense sets of constraints", abstract). Internal to libparam.
//
// Why: with many features on a coarse mesh (64 per 5k-vertex FAUST body) the path network
// runs paths side by side, so it needs well over a thousand Steiner vertices, and merging them
// back leaves folds next to fixed features that no local untangling repairs (measured: every
// network variant fails). So the network triangulates a well-spread subset of the features
// (the sparse case, which works), and the other features are then carried onto their targets
// by a smooth flow of the sphere, checked with the exact predicate at every step.
//
// Why the subset grows: the network constrains only its subset, so the stretch-optimal map
// leaves the other features where stretch puts them, in places on the far side of a network
// feature or of another feature (faust5k 013 with 64 landmarks: a feature 0.24 rad from its
// target whose great arc runs within 0.002 rad of a network feature; the flow then has to
// squeeze the mesh between them below its resolution and stalls). When the flow fails, the
// features that pass others (passing_features) and those nearest the faces that kept flipping
// (WarpStats::culprits) join the network, which routes them by paths, on the right side.
#pragma once

#include <functional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit::detail {

/// Above this many features the constrained stage routes its path network through a subset.
constexpr int kDenseFeatureThreshold = 32;
/// Size of that subset to start from: the first that works of these (a size whose network's
/// Steiner vertices cannot be removed gives way to the next, which routes other paths).
constexpr int kDenseNetworkSizes[] = {24, 16, 20, 32};
constexpr int kDenseNetworkFeatures = kDenseNetworkSizes[0];
/// Attempts per starting size, each adding to the network the features the previous warp
/// could not carry (measured on faust5k 000 + 013: at most 3 were needed with 64 and 128
/// landmarks; each costs one network and one stretch optimization).
constexpr int kDenseGrowRounds = 6;

/// `count` indices of well-spread targets: farthest-point samples on the sphere (angles),
/// starting with target 0, ties to the lower index. Sorted ascending.
std::vector<int> spread_subset(const std::vector<Eigen::Vector3d>& targets, int count);

/// Two features "pass" each other when, moving along their great arcs at proportional speeds,
/// they come closer than this fraction of their distance at both ends.
constexpr double kPassingRatio = 0.5;

/// Indices of features whose arcs from `from` to `to` pass another feature (the one of each
/// such pair that travels farther; a feature with from == to stands still). Sorted.
std::vector<int> passing_features(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to);

struct WarpStats {
  int steps = 0;     ///< accepted flow steps
  int rejected = 0;  ///< steps halved because a face flipped
  int reshaped = 0;  ///< slivers reshaped (untangle_patch) because they flipped at any step
  int relaxed = 0;   ///< calls of the relax function
  std::vector<int> culprits;  ///< on failure: indices of the features nearest the faces that kept flipping
};

/// Moves the map S (a bijection of the mesh with faces F onto the sphere: 0 flipped faces)
/// so that vertex fv[j] lands exactly on targets[j] for every j, by a flow of the sphere: each
/// step moves every feature a fraction of the way along its great arc and displaces all
/// vertices by the compactly supported radial-basis interpolant of the features' displacements (features
/// already on target do not move). A step that flips a face (exact predicate) is halved.
/// A face that flips however small the step (a sliver wider than the field's support) is
/// reshaped with untangle_patch against its shape in the mesh X, features fixed (at most
/// 100 times; then the warp gives up and names in stats->culprits the two
/// moving features nearest each face that still flips).
/// On success S has 0 flipped faces and every feature exactly on its target; otherwise
/// SolverFailed and S unchanged. Deterministic (one thread).
///
/// `relax`, if given, is called on the current map when a step keeps flipping faces however
/// small it gets: it must keep the map bijective and the features where they are (the
/// constrained stage passes one stretch-optimizer pass with the features fixed). The mesh
/// squeezed between features that pass close to each other then spreads out again, and the
/// flow goes on (at most kMaxRelaxes times).
using WarpRelaxFn = std::function<Status(RowMat3d* S)>;
constexpr int kMaxRelaxes = 12;
Status warp_features_to_targets(const RowMat3d& X, const RowMat3i& F, const std::vector<int>& fv,
                                const std::vector<Eigen::Vector3d>& targets, const ProgressFn& progress, RowMat3d* S,
                                WarpStats* stats = nullptr, const WarpRelaxFn& relax = {});

/// The flow's field at a vertex sums the kernels of the features within `support` of it, in
/// feature order. Summing over every feature was most of the flow's time (5k vertices x 272
/// features per step in the correspondence refinement: 18% of a FAUST collection's CPU), and
/// most terms are exactly zero. This grid over [-1, 1]^3 (cells of half the support) lists
/// per cell, in ascending order, every feature whose support can reach a point of the cell
/// (the cell's box within support of the centre, with a margin far above rounding), so a
/// vertex visits a superset of its contributing features in the same order, and the field
/// is the same to the bit.
class SupportCells {
 public:
  SupportCells(const std::vector<Eigen::Vector3d>& centres, double support);
  /// Ascending indices of the centres whose support may reach x (every centre c with
  /// |x - c| < support is listed; a point outside [-1, 1]^3 gets every centre).
  std::span<const int> near(const Eigen::Vector3d& x) const;
  int cells_per_axis() const { return n_; }

 private:
  size_t key(const int* idx) const;  // a cell's index from its three coordinates
  double cell_;
  int n_;
  std::vector<int> start_, entries_;  // per cell (CSR): the centres listed for it
  std::vector<int> all_;              // 0 .. centres - 1, for a point outside [-1, 1]^3
};

/// Flow targets taken from a fitted correspondence (the correspondence refinement): marks the
/// samples `spread` that lie on or next to a face of F that the composed map Sc inverts (the
/// vertices of those faces and of every face touching them; exact predicate) as having no
/// target (inside[w] = 0) and returns how many it marked. Where a fit folds a member's map,
/// its targets ask for a fold that no bijective flow makes, whichever samples carry them.
int leave_out_folded_samples(const RowMat3i& F, const RowMat3d& Sc, const std::vector<int>& spread,
                             std::vector<char>* inside);

/// The fitted correspondence between the flow's samples (the correspondence refinement): each
/// vertex v with movable[v] != 0 moves from S's point toward T's along the chord (projected),
/// the whole way or 1/2, 1/4, 1/8 of it, the first that keeps every face around v positive
/// (exact predicate) and at least half as large as it was (signed volume with the origin: no
/// move makes a sliver the stretch passes then cannot undo; over `sweeps` sweeps a face may
/// shrink to 1/2^sweeps), else it stays. Sweeps go in vertex order (deterministic). Returns the
/// moves made. Keeps S bijective (each move stays in the kernel of v's ring).
int snap_toward_targets(const RowMat3i& F, const RowMat3d& T, const std::vector<char>& movable, int sweeps,
                        RowMat3d* S);

}  // namespace spherekit::detail
