// Corresponding landmarks proposed automatically for a set of genus-0 meshes (issue 25), so
// that the consistent parameterization (Asirvatham, Praun, Hoppe 2005 §3: "the user
// identifies corresponding feature points") can run on a folder of meshes without hand-made
// feature files.
//
// 1. Extremities: maxima of the average geodesic distance (AGD; Kim, Lipman, Funkhouser 2011
//    use it to sample "extremal" points) over a geodesic disc; AGD is estimated from
//    farthest-point-sampled sources with Dijkstra on the edge graph.
// 2. Matching without user input: an assignment of the reference member's extremities to each
//    member's (partial, injective) minimising the differences of their pairwise geodesic
//    distances normalised by sqrt(area), enumerated with branch and bound.
// 3. Mirror: intrinsic distances cannot tell a shape from its mirror image; the orientation
//    of triples of matched points (the turn from one tangent direction to another about the
//    outward normal) can. Among the best assignments the one whose triples turn the same way
//    as the reference's is taken; when orientation cannot decide and the mirrored assignment
//    costs about the same, the member is flagged `mirror_ambiguous` (never guessed silently).
// 4. Further points by farthest-point sampling on the reference, located on every member by
//    their geodesic distances to the points already matched.
#pragma once

#include <string>
#include <vector>

#include "spherekit/features.h"
#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit {

struct ProposeLandmarksOptions {
  int agd_sources = 24;          ///< farthest-point sources of the AGD estimate (>= 4)
  int max_extremities = 10;      ///< at most this many extremities per member (3..16)
  double extremity_radius = 0.15;  ///< an extremity dominates the AGD on this geodesic disc (x sqrt(area))
  int extra_points = 0;          ///< further points by farthest-point sampling (>= 0)
  int reference = -1;            ///< the member the others are matched to; -1: the one of the first 8 matching the others best
};

/// How one member was matched to the reference.
struct LandmarkMemberMatch {
  double cost = 0;                 ///< mean |pairwise distance difference| / sqrt(area) of the chosen assignment
  double mirrored_cost = -1;       ///< the best assignment turning the other way (-1: none found)
  double orientation_agreement = 1;  ///< -1..1: how the chosen assignment's triples turn relative to the reference's
  bool mirror_resolved = false;    ///< the intrinsically best assignment was the mirror image and orientation chose the other
  bool mirrored = false;           ///< the member appears to be a mirror image of the reference (orientation disagrees)
  bool mirror_ambiguous = false;   ///< orientation could not decide between two near-equal assignments
};

struct ProposeLandmarksResult {
  std::vector<std::string> names;               ///< lm0, lm1, ... (extremities first)
  int reference = 0;                            ///< the member the others were matched to
  int extremities = 0;                          ///< how many of `names` are extremities
  std::vector<std::vector<Landmark>> landmarks; ///< per member, in the order of `names`
  std::vector<std::vector<double>> confidence;  ///< per member and name, 0..1 (1 for the reference)
  std::vector<LandmarkMemberMatch> members;     ///< per member (the reference's is trivially 0 / 1)
  std::vector<int> extremities_found;           ///< per member, before matching
};

/// Proposes corresponding landmarks. Meshes: one connected component each (holes allowed),
/// faces indexing their vertices, at least 4 vertices.
/// Errors: InvalidArgument (fewer than one mesh, options out of range, reference out of
/// range), InvalidInput (a mesh with a bad face index, several components or zero area; the
/// message names the member index), Cancelled.
Result<ProposeLandmarksResult> propose_landmarks(const std::vector<TriMesh>& meshes,
                                                 const ProposeLandmarksOptions& options = {},
                                                 const ProgressFn& progress = {});

}  // namespace spherekit
