// Shared by the scale tests (issue 23): a generated collection, the files a collection folder
// lists, a child process that can be killed, map validity by the exact predicate.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace spherekit::test {

/// The collection as a reader sees it: collection.json, features.txt and every map the
/// manifest lists, name -> bytes. Empty when the manifest cannot be parsed.
std::map<std::string, std::string> collection_files(const std::string& dir);

/// Every regular file of `dir` whose name does not start with '.', name -> bytes.
std::map<std::string, std::string> visible_files(const std::string& dir);

/// Starts `argv` (argv[0] a path) with stdin, stdout and stderr on /dev/null; returns its pid.
int spawn_quiet(const std::vector<std::string>& argv);
/// Waits for `pid`; returns its exit code, or 128 + signal.
int wait_for(int pid);

/// Number of problems of every listed map of the collection: unreadable, not of its mesh,
/// flipped faces by the exact predicate, a feature vertex farther than 1e-12 rad from its
/// location. 0 for a valid collection.
int collection_map_problems(const std::string& dir, std::string* first_problem);

/// Names of the siblings of `dir` (same parent) starting with "." + its name: staging and
/// set-aside leftovers.
std::vector<std::string> hidden_siblings(const std::string& dir);

}  // namespace spherekit::test
