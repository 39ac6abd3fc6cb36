// `spherekit correspond` as a job: surface points of one collection member mapped to another
// through the common sphere, and the measured error of that map against ground truth (the
// Princeton protocol of shared/tools/evalcorr.py).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "spherekit/correspondence.h"
#include "spherekit/pipeline/json.h"
#include "spherekit/status.h"

namespace spherekit::pipeline {

struct CorrespondJob {
  std::string collection, a, b;  ///< the collection folder and two members (their mesh files)
  std::string points;            ///< points on A (`x y z` lines), sent to B
  std::string output;            ///< where B's points go (empty: returned in `points_text` only)
  std::vector<std::string> corr;  ///< ground truth: A.corr.txt B.corr.txt (vertex k pairs with vertex k) ...
  std::vector<std::string> gt;    ///< ... or A.gt.txt B.gt.txt (template ids)
  int samples = 0;                ///< measure at most this many evenly spaced pairs (0: all)
};

struct CorrespondResult {
  std::string points_text;  ///< B's points, `x y z` lines (when `points` was given)
  int points_in_holes = 0;  ///< of them, how many fell into holes of B (nearest surface point given)
  std::optional<CorrespondenceError> error;  ///< with ground truth
};

/// Errors: InvalidArgument (nothing to do), the collection's and the files' errors (naming
/// them), InvalidInput (a mesh that is not the mapped member, vertex pairs out of range).
Result<CorrespondResult> correspond_members(const CorrespondJob& job);

/// The measures with shared/tools/evalcorr.py's keys.
Json to_json(const CorrespondenceError& e);

}  // namespace spherekit::pipeline
