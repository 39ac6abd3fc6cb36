// The subcommands of `spherekit`. Each register_<cmd>() adds one CLI::App subcommand whose
// callback parses nothing further, runs the command and records its exit code with
// cli::set_exit_code() (see cli_common.h). main.cpp only wires them together.
#pragma once

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace spherekit {
struct SphereParamOptions;
}

namespace spherekit::cli {

void register_check(CLI::App& app);    // cmd_check.cpp:   mesh report, pinched-vertex repair
void register_param(CLI::App& app);    // cmd_param.cpp:   unconstrained spherical parameterization
void register_eval(CLI::App& app);     // cmd_eval.cpp:    measures of any sphere map (= evalsphere.py)
void register_eval_surface(CLI::App& app);  // cmd_eval_surface.cpp: distance/PSNR of two surfaces (remesh_error)
void register_samples(CLI::App& app);  // cmd_samples.cpp: writes the built-in sample collection
void register_bench(CLI::App& app);    // cmd_bench.cpp:   per-mesh time/memory/efficiency vs. the reference
void register_run(CLI::App& app);      // cmd_run.cpp:     the main job: check + param + eval + report
void register_convert(CLI::App& app);  // cmd_convert.cpp: sphere map -> octahedral geometry image (EXR)
void register_consistent(CLI::App& app);  // cmd_consistent.cpp: consistent collection + add
void register_correspond(CLI::App& app);  // cmd_correspond.cpp: point transfer and its error
void register_transfer(CLI::App& app);    // cmd_transfer.cpp: colours/normals/uv/texture A -> B
void register_morph(CLI::App& app);       // cmd_morph.cpp:    morph sequence between two members
void register_pca(CLI::App& app);         // cmd_pca.cpp:      mean shape, components, errors, compression

/// `spherekit consistent -o OUTPUT MESH... [--report REPORT]` with default collection
/// options (feature files beside the meshes); `run` uses it for the samples. Returns the
/// exit code.
int run_consistent_job(const std::vector<std::string>& meshes, const std::string& output, const std::string& report,
                       bool quiet, const SphereParamOptions& sphere);

/// The applications with their default options, for `run` (exit codes as the commands):
/// `transfer DIR --from FROM --to TO --what WHAT -o OUTPUT [--attributes A] [--report R]`,
/// `morph DIR A B -o OUTPUT`, `pca DIR -o OUTPUT`. Empty `attributes`/`report`: not given.
int run_transfer_job(const std::string& dir, const std::string& from, const std::string& to, const std::string& what,
                     const std::string& output, const std::string& attributes, const std::string& report, bool quiet);
int run_morph_job(const std::string& dir, const std::string& a, const std::string& b, const std::string& output,
                  bool quiet);
int run_pca_job(const std::string& dir, const std::string& output, bool quiet);

}  // namespace spherekit::cli
