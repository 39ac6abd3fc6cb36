// In-memory entry points of the feature-file readers (feature_io.h reads the file, then
// parses it here). The fuzz harnesses (tools/fuzz) call these directly; `path` only names
// the file in messages.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "spherekit/formats/feature_io.h"

namespace spherekit::formats::detail {

Result<std::vector<Landmark>> parse_landmarks(const std::string& path, std::string_view bytes, int num_vertices);
Result<std::vector<SpherePoint>> parse_sphere_points(const std::string& path, std::string_view bytes,
                                                     bool require_unit);
Result<std::vector<LandmarkTarget>> parse_landmark_targets(const std::string& path, std::string_view bytes,
                                                           int num_vertices);

}  // namespace spherekit::formats::detail
