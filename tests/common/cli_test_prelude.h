// The names every command-line test file uses, declared once: the runner (`sk`, CliRun), shell
// quoting (`q`), reading outputs back (`slurp`, `read_json`), std::filesystem as `fs` and
// nlohmann's `json`. Include it after the other headers of a test file; for test files only.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "cli_shorthands.h"
#include "test_paths.h"

namespace fs = std::filesystem;
using nlohmann::json;
using spherekit::test::CliRun;
using spherekit::test::q;
using spherekit::test::read_json;
using spherekit::test::sk;
using spherekit::test::slurp;
