// `spherekit landmarks` as a job: corresponding landmarks proposed for a set of meshes
// (spherekit/propose_landmarks.h), one `NAME.lm.txt` per mesh and a report of how confident
// each match is (issue 25).
#pragma once

#include <string>
#include <vector>

#include "spherekit/pipeline/json.h"
#include "spherekit/progress.h"
#include "spherekit/propose_landmarks.h"
#include "spherekit/status.h"

namespace spherekit::pipeline {

struct LandmarksJob {
  std::vector<std::string> meshes;  ///< mesh files
  std::string output_dir;           ///< where `NAME.lm.txt` go; empty: beside each mesh (where `consistent` looks)
  bool write = true;                ///< false: compute only (`run` writes into its own folder)
  ProposeLandmarksOptions options;
};

struct LandmarksResult {
  std::vector<std::string> files;  ///< the landmark file of each mesh (written when job.write)
  ProposeLandmarksResult proposal;
  double seconds = 0;
};

/// The landmark file of `mesh` in `output_dir` (empty: beside the mesh): `<stem>.lm.txt`.
std::string landmark_file_for(const std::string& mesh, const std::string& output_dir);

/// Reads the meshes (errors name the file), proposes, writes every file only when all were
/// proposed (each atomically). Errors: InvalidArgument (no meshes), the readers' errors,
/// propose_landmarks' errors with the member's file instead of its index, IoError.
Result<LandmarksResult> propose_landmark_files(const LandmarksJob& job, const ProgressFn& progress = {});

/// The report: per member its file, landmark file, match measures and landmarks with confidence.
Json to_json(const LandmarksJob& job, const LandmarksResult& result);

}  // namespace spherekit::pipeline
