// Small file helpers every test family uses (once here instead of per test file).
#pragma once

#include <string>
#include <vector>

namespace spherekit::test {

/// Writes `text` to `path` (binary, replacing the file).
void write_text(const std::string& path, const std::string& text);
/// The names of the entries of `dir` (files and folders, hidden ones too), sorted.
std::vector<std::string> files_in(const std::string& dir);

}  // namespace spherekit::test
