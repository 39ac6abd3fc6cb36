// Where test data lives. The shared meshes (../shared next to the checkout) are optional:
// tests that use them skip with a message when they are absent.
#pragma once

#include <optional>
#include <string>

#include "test_skip.h"

namespace spherekit::test {

/// Absolute path of the shared/ folder beside the checkout (SPHEREKIT_SHARED_DIR overrides),
/// or nullopt when it does not exist.
std::optional<std::string> shared_dir();
/// shared_dir() + "/meshes", or nullopt.
std::optional<std::string> shared_meshes_dir();
/// A fresh, empty temporary directory for one test (under the build tree).
std::string temp_dir(const std::string& name);

}  // namespace spherekit::test

/// Use at the top of a TEST_CASE that needs ../shared/meshes: skips with a message.
#define SPHEREKIT_REQUIRE_SHARED_MESHES(var)                                             \
  auto var##_opt = ::spherekit::test::shared_meshes_dir();                                \
  if (!var##_opt) {                                                                       \
    SPHEREKIT_SKIP("../shared/meshes is absent (set SPHEREKIT_SHARED_DIR)");              \
  }                                                                                       \
  const std::string var = *var##_opt
