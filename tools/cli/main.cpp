// `spherekit`: one program, one subcommand per pipeline stage. main() only wires the
// subcommands together and turns the outcome into an exit code; the commands live in
// cmd_*.cpp, the algorithms in the libraries.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/version.h"

int main(int argc, char** argv) {
  using namespace spherekit;
  cli::install_signal_handlers();

  CLI::App app{
      "SphereKit maps genus-0 triangle meshes bijectively onto the unit sphere, minimizing stretch\n"
      "(Praun & Hoppe 2003), and measures such maps. Run a subcommand with --help for details.",
      "spherekit"};
  app.set_version_flag("--version", std::string("spherekit ") + kVersion);
  app.require_subcommand(1);
  app.footer(
      "Examples:\n"
      "  spherekit run                         # the main job on the built-in samples -> ./spherekit-out\n"
      "  spherekit check bunny.obj --json      # structural report\n"
      "  spherekit param bunny.obj -o bunny.sphere.obj --report bunny.json\n"
      "  spherekit eval bunny.obj bunny.sphere.obj --json\n"
      "  spherekit consistent -o cats cat0.obj cat2.obj cat5.obj   # features coincide on the sphere\n"
      "\n"
      "Exit codes: 0 ok, 2 usage error, 3 invalid/malformed/unsupported input, 4 I/O error,\n"
      "5 solver failed (including a non-bijective result), 6 internal error, 130 cancelled.");

  cli::register_check(app);
  cli::register_param(app);
  cli::register_eval(app);
  cli::register_eval_surface(app);
  cli::register_samples(app);
  cli::register_bench(app);
  cli::register_run(app);
  cli::register_convert(app);
  cli::register_consistent(app);
  cli::register_correspond(app);
  cli::register_landmarks(app);
  cli::register_transfer(app);
  cli::register_morph(app);
  cli::register_pca(app);
  cli::register_submit(app);

  try {
    // The chosen subcommand's callback runs inside parse() and records its exit code.
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version are "errors" with exit code 0; CLI11 prints them.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    // CLI11's own codes (105-110) would collide with nothing of ours but mean nothing to
    // scripts either: every usage error is exit 2, reported on one line like other errors.
    std::string what = e.what();
    if (what.empty()) what = "invalid command line";
    cli::print_error(Status(ErrorCode::InvalidArgument, what + " (run 'spherekit --help')"));
    return cli::kUsageExitCode;
  } catch (const std::bad_alloc&) {
    return cli::print_error(Status(ErrorCode::Internal, "out of memory"));
  } catch (const std::exception& e) {
    // The libraries return Status; anything thrown here is a bug in this program.
    return cli::print_error(Status(ErrorCode::Internal, std::string("internal error: ") + e.what()));
  }
  return cli::exit_code();
}
