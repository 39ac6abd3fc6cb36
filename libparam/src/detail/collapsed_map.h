// Telling a step-6 map that completed but collapsed (or wound its network round) from one that
// merely moved its features
// (Asirvatham, Praun, Hoppe 2005 §3, step 6).
#pragma once

#include <cstddef>
#include <vector>

#include "spherekit/constrained_param.h"

namespace spherekit::detail {

/// Step 6 maps every mesh to the refined locations F; moving features from F' to F costs a
/// map a little stretch (ICT heads, FAUST, TOSCA cats, the built-in samples, given or proposed
/// landmarks: each keeps 0.96-1.01x its step-2 efficiency; the reference, whose step-2 map is
/// its unconstrained one, 0.80 in the non-isometric pair bunny + gargoyle). Where F forces a
/// mesh's path network to wind round (a path several times as long as its shortest route),
/// the map completes with a fraction of that. Returns the first mesh whose map to F keeps
/// less than `fraction` of its map to F' (`to_initial`, step 2), or -1. Both vectors hold one
/// entry per mesh.
inline int first_collapsed_map(const std::vector<ConstrainedParamResult>& to_final,
                               const std::vector<ConstrainedParamResult>& to_initial, double fraction) {
  for (size_t i = 0; i < to_final.size() && i < to_initial.size(); ++i)
    if (to_final[i].efficiency < fraction * to_initial[i].efficiency) return static_cast<int>(i);
  return -1;
}

/// A step-6 map can keep its stretch and still be wrong: where F turns a mesh's network so
/// that a path winds round (a path more than twice its shortest route), the regions between
/// the paths no longer match the other meshes'. Normal networks (ICT heads, FAUST, TOSCA cats,
/// given or proposed landmarks, steps 2 and 6) have no path above 1.25x; ICT heads with the
/// landmarks on the face and the head's top had step-6 paths of 2.47x and 2.76x (1.18x and
/// 1.22x to F') at 0.94-0.96x their step-2 efficiency, and correspondence errors of
/// 0.045-0.058 against 0.008-0.015 with the step-2 maps. Returns the first mesh whose
/// longest path to F is above `limit` and above `growth` times its longest path to F' (a
/// mesh that winds as much to F' gains nothing from falling back), or -1.
inline int first_wound_map(const std::vector<ConstrainedParamResult>& to_final,
                           const std::vector<ConstrainedParamResult>& to_initial, double limit, double growth) {
  for (size_t i = 0; i < to_final.size() && i < to_initial.size(); ++i) {
    const double r = to_final[i].network.max_ratio;
    if (r > limit && r > growth * to_initial[i].network.max_ratio) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace spherekit::detail
