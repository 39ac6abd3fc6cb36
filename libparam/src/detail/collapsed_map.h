// Telling a step-6 map that completed but collapsed from one that merely moved its features
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

}  // namespace spherekit::detail
