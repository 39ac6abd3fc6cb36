// The parts of `spherekit run` (cmd_run.cpp) that live in their own files.
#pragma once

#include <string>

#include "cli_common.h"

namespace spherekit::cli {

/// The geometry-image size of the main job, per mesh and per collection member (as
/// `convert --gi 129`), and its PSNR sample count per direction: lower than convert's default
/// so the job stays fast.
constexpr int kRunImageSize = 129;
constexpr int kRunPsnrSamples = 100000;

/// The collection half of the main job (run_collection.cpp): with the consistent collection
/// in `col_dir`, converts every member into OUT/assets (as `convert --collection`: 129 x 129
/// images with PNG previews, 3 glTF levels of detail, cage 8 with 9 x 9 scalar displacement)
/// and runs the applications into OUT/apps (colour and normal transfer, a morph of the first
/// two members, PCA with the compression experiment). Adds what it made to `site` (the
/// results page's description, site_page.h: models, morph, plots, tables) and `report`.
/// Progress and results go to stdout/stderr unless `quiet`. Returns the exit code (0: all ran).
int run_collection_stages(const std::string& col_dir, const std::string& out_dir, bool quiet, Json& site, Json& report);

}  // namespace spherekit::cli
