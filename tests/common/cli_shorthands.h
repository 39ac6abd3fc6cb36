// Shorthands of the end-to-end tests that run this build's `spherekit` (SPHEREKIT_EXE, defined
// per test target): run it, quote a shell word, read a JSON file a command wrote.
#pragma once

#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"

namespace spherekit::test {

#ifdef SPHEREKIT_EXE
/// `spherekit ARGS`, output captured into `capture_dir` (see run_cli).
inline CliRun sk(const std::string& args, const std::string& capture_dir) {
  return run_cli(SPHEREKIT_EXE, args, capture_dir);
}
#endif

/// `s` as one shell word.
inline std::string q(const std::string& s) { return shell_quote(s); }
inline std::string quote(const std::string& s) { return shell_quote(s); }

/// The failure contract of every command: exit code `code`, exactly one stderr line starting
/// `spherekit: error: ` that contains `what`.
inline void require_failure(const CliRun& r, int code, const std::string& what) {
  INFO("stdout: " << r.out << "\nstderr: " << r.err);
  CHECK(r.exit_code == code);
  CHECK(r.err.rfind("spherekit: error: ", 0) == 0);
  CHECK(r.err.find(what) != std::string::npos);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
}
/// The same, the line also naming `file` (by its file name).
inline void require_failure(const CliRun& r, int code, const std::string& file, const std::string& problem) {
  require_failure(r, code, problem);
  CHECK(r.err.find(std::filesystem::path(file).filename().string()) != std::string::npos);
}

/// The JSON document in `path`; fails the test (REQUIRE) when it does not parse.
inline nlohmann::json read_json(const std::string& path) {
  nlohmann::json j = nlohmann::json::parse(slurp(path), nullptr, /*allow_exceptions=*/false);
  INFO("file: " << path);
  REQUIRE_FALSE(j.is_discarded());
  return j;
}

}  // namespace spherekit::test
