// Skips that ctest reports as skips. Catch2 v2 has no SKIP: a test that cannot run here (no
// ../shared meshes, no npm tools, no browser, running as root) calls SPHEREKIT_SKIP(reason),
// which prints the reason and returns. At the end of the test case a listener (test_skip.cpp)
// prints the marker line "SPHEREKIT-SKIP: reason", which the ctest property
// SKIP_REGULAR_EXPRESSION (tests/CMakeLists.txt) turns into "Skipped". The marker is printed
// only if no assertion of the test case failed: ctest's skip overrides a failure, and a
// failure must never read as a skip.
#pragma once

#include <catch2/catch.hpp>
#include <sstream>
#include <string>

namespace spherekit::test {

/// Records that the running test case skipped (part of) its checks for `reason`.
void note_skip(const std::string& reason);

}  // namespace spherekit::test

/// Notes the skip with its reason (printed at once, and as the marker at the test case's end)
/// and returns from the enclosing test case (or section).
#define SPHEREKIT_SKIP(msg)                                      \
  do {                                                           \
    std::ostringstream sk_skip_reason_;                          \
    sk_skip_reason_ << msg;                                      \
    ::spherekit::test::note_skip(sk_skip_reason_.str());         \
    WARN("SKIPPED: " << sk_skip_reason_.str());                  \
    return;                                                      \
  } while (0)
