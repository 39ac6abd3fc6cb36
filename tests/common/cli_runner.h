// Helpers for end-to-end tests that run a program through the shell and capture its output.
#pragma once

#include <string>

namespace spherekit::test {

/// The whole contents of the file at `path` (empty if it cannot be read).
std::string slurp(const std::string& path);
/// `s` in single quotes, for use as one shell word.
std::string shell_quote(const std::string& s);
/// Runs `cmd` through the shell with stdin from /dev/null, stdout to `out_file` and stderr to
/// `err_file`; returns the exit code, or -1 if it did not exit normally.
int run_shell(const std::string& cmd, const std::string& out_file, const std::string& err_file);

/// The outcome of one run_cli: exit code and captured stdout/stderr.
struct CliRun {
  int exit_code = -1;
  std::string out, err;
};

/// Runs `EXE ARGS` with stdout/stderr captured into `capture_dir`/stdout.txt and stderr.txt
/// (never the folder whose contents a test inspects).
CliRun run_cli(const std::string& exe, const std::string& args, const std::string& capture_dir);

}  // namespace spherekit::test
