// The collection half of the main job (main_job_collection.cpp). Internal to spherekit::pipeline.
#pragma once

#include <string>

#include "spherekit/pipeline/main_job.h"

namespace spherekit::pipeline::detail {

/// With the consistent collection in `col_dir`: converts every member into OUT/assets (as
/// `convert --collection`: 129 x 129 images with previews, 3 glTF levels of detail, cage 8
/// with 9 x 9 scalar displacement) and runs the applications into OUT/apps (colour and normal
/// transfer, a morph of the first two members, PCA with the compression experiment). Adds what
/// it made to `site` (models, morphs, plots, tables) and `report`.
/// `threads`: of every stage (0: all cores; the outputs do not depend on it).
Status run_collection_stages(const std::string& col_dir, const std::string& out_dir, int threads,
                             MainJobObserver& observer, Json& site, Json& report);

}  // namespace spherekit::pipeline::detail
