// The browser tests' set-up (site_browser_test.cpp, site_landmarks_test.cpp): the results
// page's viewer and the browser tools installed by scripts/setup_viewer.sh --browser
// (idempotent, no network once installed), and SPHEREKIT_VIEWER_DIR pointed at them so that
// `spherekit run` copies them into its page.
#pragma once

#include <cstdlib>
#include <string>

#include "cli_runner.h"
#include "test_paths.h"

namespace spherekit::test {

struct BrowserSetup {
  std::string viewer;  ///< the viewer folder (node_modules with playwright-core, dist/)
  bool ready = false;  ///< node, npm, the packages and Chromium are there
  std::string error;   ///< setup_viewer.sh's stderr when not ready: the skip's message
};

inline BrowserSetup setup_browser_viewer() {
  BrowserSetup s;
  if (const char* env = std::getenv("SPHEREKIT_VIEWER_DIR"); env && *env)
    s.viewer = env;
  else if (const char* home = std::getenv("HOME"); home && *home)
    s.viewer = std::string(home) + "/.cache/spherekit/viewer";
  else
    s.viewer = std::string(SPHEREKIT_BINARY_DIR) + "/viewer";
  const std::string logs = temp_dir("site_browser_setup");
  s.ready = run_shell("bash " + shell_quote(std::string(SPHEREKIT_SOURCE_DIR) + "/scripts/setup_viewer.sh") + " " +
                          shell_quote(s.viewer) + " --browser",
                      logs + "/out.txt", logs + "/err.txt") == 0;
  if (!s.ready) s.error = slurp(logs + "/err.txt");
  ::setenv("SPHEREKIT_VIEWER_DIR", s.viewer.c_str(), 1);
  return s;
}

}  // namespace spherekit::test
