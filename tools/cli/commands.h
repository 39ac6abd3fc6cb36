// The subcommands of `spherekit`, and the summaries of the jobs' results they print
// (summaries.cpp; `run` prints them for its stages too). Each register_<cmd>() adds one
// CLI::App subcommand whose callback parses nothing further, runs the command and records its
// exit code with cli::set_exit_code() (see cli_common.h). main.cpp only wires them together.
#pragma once

#include <string>
#include <vector>

#include "spherekit/status.h"

namespace CLI {
class App;
}

namespace spherekit {
struct SphereParamOptions;
namespace scheduler {
struct CollectionPlanOptions;
}
namespace pipeline {
struct ConvertCollectionResult;
struct ConvertMeshResult;
struct LoadedMesh;
struct MakeCollectionResult;
struct AddToCollectionJob;
struct AddToCollectionResult;
struct TransferJob;
struct TransferResult;
struct MorphJob;
struct MorphResult;
struct PcaJob;
struct PcaResult;
}
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
void register_landmarks(CLI::App& app);   // cmd_landmarks.cpp:  proposed corresponding landmarks
void register_transfer(CLI::App& app);    // cmd_transfer.cpp: colours/normals/uv/texture A -> B
void register_morph(CLI::App& app);       // cmd_morph.cpp:    morph sequence between two members
void register_pca(CLI::App& app);         // cmd_pca.cpp:      mean shape, components, errors, compression
void register_submit(CLI::App& app);      // cmd_submit.cpp:   large collections as job arrays (local or Slurm)

/// The report `check` prints for one mesh (its structure and param's verdict).
void print_check_summary(const pipeline::LoadedMesh& mesh, const Status& verdict);
/// The summary `convert` prints for one mesh.
void print_mesh_summary(const pipeline::ConvertMeshResult& result);
/// The summary `convert --collection` prints (per member on stderr, the total on stdout).
void print_collection_summary(const pipeline::ConvertCollectionResult& result);

/// What `consistent` prints: the step-6 warning (stderr) and the summary tables.
void print_collection_warning(const pipeline::MakeCollectionResult& result);
void print_consistent_summary(const pipeline::MakeCollectionResult& result, const std::string& output,
                              double wall_seconds);
/// What `add` prints (a registered map or a computed one).
void print_add_summary(const pipeline::AddToCollectionResult& result, const pipeline::AddToCollectionJob& job);
/// The plan line `submit` prints on stderr before running: members, the subset, its memory.
void print_submit_plan(const scheduler::CollectionPlanOptions& options, int k_memory, double joint_memory_mb,
                       int remesh_size, const std::string& scheduler_name);

/// The summaries `transfer`, `morph` and `pca` print (the main job prints them too).
void print_transfer_summary(const pipeline::TransferResult& result, const pipeline::TransferJob& job);
void print_morph_summary(const pipeline::MorphResult& result, const pipeline::MorphJob& job);
void print_pca_summary(const pipeline::PcaResult& result, const pipeline::PcaJob& job);

}  // namespace spherekit::cli
