// Landmarks on the rims of corresponding openings (issue 25). A family of scans or models with
// the same openings (a face's eyes and mouth, a body's open neck) has, on each opening's rim,
// points as well defined as any extremity: the two ends of an elongated rim (the corners of an
// eye or a mouth) and, on each side between them, the rim point farthest from the line
// through the ends (the middle of a lid or a lip). Extremities (maxima of the average geodesic
// distance) cannot see them: a rim is a feature of the boundary, not of the distance field.
//
// Matching without user input, given landmarks already matched on every member (the
// extremities): an opening is described by its geodesic distances to those landmarks and its
// perimeter, both relative to the surface's size; a reference opening and a member's are
// matched when each is the other's best, clearly ahead of the runner-up (a left eye against a
// right one differs in its distances to the ears). The two ends are told apart the same way,
// and the sides between them follow from the rim's orientation (the surface on its left, the
// same on every consistently oriented member). An opening that is round (no ends), ambiguous
// or missing on some member gives no points: nothing is guessed.
#pragma once

#include <vector>

#include "spherekit/mesh.h"

namespace spherekit::detail {

struct RimOptions {
  double min_elongation = 1.2;   // rim diameter / its width (sum of both sides' distances from the chord)
  double min_separation = 0.05;  // a rim point this close (x sqrt(area)) to a landmark is left out, to an earlier rim point crowded
  double max_cost = 0.25;        // mean relative distance difference of a matched opening
  double margin = 0.7;           // the best match costs at most this share of the runner-up's
};

struct RimPoint {
  std::vector<int> vertex;  // per member (member order): the rim vertex's nearest neighbour off every rim
  // Closer than min_separation to a point before it on some member (an eye's lid middles next to
  // its corners): precise, so a judge of other matches, but too crowded to be a feature of the
  // consistent method.
  bool crowded = false;
};

// One opening's shape (its rim's vertices, ends, sides), which no landmark changes.
struct Rim {
  std::vector<int> v;          // rim vertices, the surface on the left
  double perimeter = 0;        // x sqrt(area)
  int i = 0, j = 0;            // positions of the two ends (i < j): the rim's diameter
  int mid_ij = 0, mid_ji = 0;  // the farthest point from the chord on each side (positions)
  double elongation = 0, bulge = 0;
  bool sharp[4] = {};          // ends i, j, middles ij, ji: a sharp extremum
};

/// The members' openings, found once; matched in rounds as landmarks accumulate.
class RimMatcher {
 public:
  /// Openings are the meshes' boundary loops; meshes without any give no points.
  RimMatcher(const std::vector<const TriMesh*>& meshes, const std::vector<double>& sqrt_area, RimOptions options = {});

  /// The points of the reference's openings not matched yet (see step_inside in the .cpp for
  /// where they sit). landmark_dist[i]: member i's geodesic distance fields (units of
  /// sqrt(area)) of the landmarks so far, in the same order on every member. Call again with
  /// the new points' fields among them: an opening whose ends the extremities could not tell
  /// apart may be told apart by another's precise points. `ref`: the same member in every call.
  std::vector<RimPoint> match(const std::vector<std::vector<const std::vector<double>*>>& landmark_dist, int ref);

 private:
  std::vector<const TriMesh*> meshes_;
  std::vector<double> sqrt_area_;
  RimOptions o_;
  std::vector<std::vector<Rim>> rims_;     // per member
  std::vector<std::vector<char>> on_rim_;  // per member and vertex
  std::vector<char> done_;                 // per reference opening: matched in an earlier round
};

}  // namespace spherekit::detail
