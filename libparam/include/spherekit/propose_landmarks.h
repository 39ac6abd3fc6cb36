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
// 3. Mirror: intrinsic distances cannot tell a shape from its mirror image, nor a
//    near-symmetric shape's left from its right. Sphere maps can (they preserve orientation):
//    the reference's unconstrained map places its extremities, each near-equal assignment of
//    a member becomes a constrained map with its extremities there (Asirvatham, Praun, Hoppe
//    2005 §4), and the one whose correspondence carries the reference's signed shape signal
//    (smoothed offset along the normal) best onto the member's wins. A left/right swap can
//    only be realised by turning the body round, face onto the back of the head.
//    Where no sphere map can be made (not genus 0), the orientation of triples of matched
//    points seen from a trilaterated centre decides. Members where neither decides are
//    flagged `mirror_ambiguous` (never guessed silently). A signal that carries no shape at
//    all (a flat figure) decides nothing: the turns do.
//    An extremity whose distances on some member are wrong far beyond that member's other
//    extremities' (matched to another feature: a tail that is no extremity there) is left out.
//    Each matched extremity then moves to the centre of its tip region (the AGD within
//    `tip_drop` of its maximum): a hand's nearly equal fingertip peaks trade places between
//    poses, the centre of the hand's tip does not.
// 4. Unstable extremities and finer peaks: an extremity with another peak beyond its tip
//    region (up to twice `extremity_radius`) rising within `tip_drop` of it sits on different
//    features on different members (a cat's head peaks at the nose on one and at an ear tip
//    on another); it is left out, and the finer peaks of its region (AGD maxima of discs of
//    `fine_radius`: a cat's ear tips) are matched among themselves, like the extremities, by
//    their distances to the stable ones and to each other, left and right by their turns
//    (peaks that fit on no assignment, a broad snout's, are left out). A stable extremity's
//    tip region may hold limb tips of its own (a hand's fingertips: AGD maxima where the AGD
//    falls at least 0.3 times as fast as the distance); they are matched the same way and
//    the one farthest from the landmarks (the thumb) is added: it fixes the limb's twist,
//    which the tip's centre alone leaves free. The maps of the chosen
//    assignments are made again with the stable ones pinned, and the finer peaks outside
//    every tip region are carried from the reference to each member through them and
//    snapped to the member's nearest such peak; those that snap on every member and snap
//    back to themselves are added.
// 5. Rim points: where the members have openings (boundary loops) that match by their
//    distances to the landmarks so far, the ends of each elongated rim and the middles of its
//    two sides (detail/rim_landmarks.h): a face's eye and mouth corners; a point crowding an
//    earlier one (an eye's lid middles) only judges. Placed to within a few edges, they then
//    judge the extremities: one whose distances to them disagree with the reference's far more
//    than theirs do among themselves is left out.
// 6. Further points by farthest-point sampling on the reference, located on every member by
//    geodesic trilateration (relative differences of their distances to the points already
//    matched); distances alone cannot tell a torso's front from its back, so among the fit's
//    best local minima the turns of the landmarks seen from the point decide (the test of
//    step 3 about one point), weighed against how much worse each fits.
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
  double tip_drop = 0.03;        ///< a matched extremity moves to the centre of its tip region: AGD within this of its own (x sqrt(area)); 0: stays at the AGD maximum
  double fine_radius = 0.08;     ///< finer AGD maxima (this disc radius, x sqrt(area)): an unstable extremity's matched among themselves, others through the sphere maps; 0: off
  bool rim_points = true;        ///< add points on the rims of openings every member has (eye and mouth corners)
  int extra_points = 0;          ///< further points by farthest-point sampling (>= 0)
  int reference = -1;            ///< the member the others are matched to; -1: the one of the first 8 matching the others best
  bool sphere_orientation = true;  ///< settle left/right by sphere maps (genus-0 members; else by turns)
  int sphere_effort = 0;         ///< effort of those maps (0..5; SphereParamOptions::effort)
  int threads = 0;               ///< worker threads of those maps; 0 = hardware (results do not depend on it)
};

/// How one member was matched to the reference.
struct LandmarkMemberMatch {
  double cost = 0;                 ///< mean |pairwise distance difference| / sqrt(area) of the chosen assignment
  double mirrored_cost = -1;       ///< the best assignment turning the other way (-1: none found)
  double orientation_agreement = 1;  ///< -1..1: how the chosen assignment's triples turn relative to the reference's
  bool mirror_resolved = false;    ///< the intrinsically best assignment was the mirror image and orientation chose the other
  bool mirrored = false;           ///< the member appears to be a mirror image of the reference (orientation disagrees)
  bool mirror_ambiguous = false;   ///< orientation could not decide between two near-equal assignments, or
                                   ///< settled left/right against the cheapest on a weak signal (agreement < 0.5)
  bool sphere_checked = false;     ///< the choice was made by sphere maps (else by turns of triples)
  double sphere_agreement = 0;     ///< -1..1: signal correlation through the chosen assignment's map
  double sphere_runner_up = -2;    ///< the same for the next best candidate (-2: none)
};

struct ProposeLandmarksResult {
  std::vector<std::string> names;               ///< lm0, lm1, ... (extremities first)
  int reference = 0;                            ///< the member the others were matched to
  int extremities = 0;                          ///< how many of `names` are extremities (including finer peaks)
  int unstable_dropped = 0;                     ///< extremities left out as unstable (another peak as high beyond the tip)
  int mismatch_dropped = 0;                     ///< extremities left out: matched to another feature on some member (most of its distances wrong there)
  int fine_matched = 0;                         ///< finer AGD peaks matched (unstable extremities' regions, then through the sphere maps)
  int rim_matched = 0;                          ///< points on the rims of corresponding openings (after the extremities)
  int rim_outliers_dropped = 0;                 ///< extremities left out: their distances to the rim points disagree (see the .cpp)
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

/// A landmark of given, corresponding landmark sets whose geodesic distances to the others on
/// one member disagree with the reference member's far beyond those among that member's other
/// landmarks (a stricter form of the rule that leaves a mismatched extremity out of a proposal,
/// step 3): most likely on another feature there (a wrong vertex index, two names swapped in one
/// file). Distances cannot see a left/right swap of a symmetric shape's pair; those pass.
struct SuspectLandmark {
  int member = 0;            ///< index into the meshes
  int landmark = 0;          ///< index into the landmark lists
  double disagreement = 0;   ///< median over its pairs of |log(d_member / d_reference)|
  /// The same over the pairs among the member's other landmarks still unreported when it was
  /// (reported while disagreement > 0.4 and > 5 typical, worst first, while more than 3 remain).
  double typical = 0;
};

/// Checks corresponding landmark sets (`landmarks[i]`: member i's vertices, the same feature at
/// the same index on every member) against the reference member's: edge-graph geodesic
/// distances / sqrt(area). Fewer than 4 or more than 64 landmarks: an empty list. Errors:
/// a mesh without faces, a vertex out of range (InvalidInput, naming the member's index).
Result<std::vector<SuspectLandmark>> suspect_landmarks(const std::vector<TriMesh>& meshes,
                                                       const std::vector<std::vector<int>>& landmarks, int reference);

}  // namespace spherekit
