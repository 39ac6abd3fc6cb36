// `spherekit samples`: writes the built-in sample collection (procedural animal-like
// genus-0 shapes with landmarks and ground-truth correspondence) to a folder.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "sample_collection.h"

namespace spherekit::cli {
namespace {

struct SamplesArgs {
  std::string output;
  bool quiet = false;
  samples::SampleCollectionOptions options;
};

int run_samples(const SamplesArgs& a) {
  std::error_code ec;
  std::filesystem::create_directories(a.output, ec);
  if (ec) return print_error(Status(ErrorCode::IoError, a.output + ": cannot create folder: " + ec.message()));

  auto collection = samples::make_sample_collection(a.options);
  if (!collection.ok()) return print_error(collection.status());
  if (Status s = samples::write_sample_collection(a.output, collection.value()); !s.ok()) return print_error(s);

  if (a.quiet) return 0;
  for (const samples::SampleMesh& m : collection.value())
    std::printf("%s/%s.obj: %lld vertices, %lld faces, %d hole%s, %zu landmarks\n", a.output.c_str(), m.name.c_str(),
                static_cast<long long>(m.mesh.V.rows()), static_cast<long long>(m.mesh.F.rows()), m.boundary_loops,
                m.boundary_loops == 1 ? "" : "s", m.landmarks.size());
  return 0;
}

}  // namespace

void register_samples(CLI::App& app) {
  auto args = std::make_shared<SamplesArgs>();
  CLI::App* cmd = add_command(
      app, "samples", "Write the built-in sample collection (meshes, landmarks, ground truth)",
      "Write the built-in sample collection to a folder: animal-like genus-0 shapes (body, legs,\n"
      "tail, head, ears) in several proportions and poses, each meshed with its own connectivity,\n"
      "some with a hole. Per member: NAME.obj (mesh), NAME.lm.txt (landmarks 'name vertex_index'),\n"
      "NAME.template.txt (ground-truth template point per vertex) and NAME.corr.txt (corresponding\n"
      "vertices, line k of every member is the same point). Deterministic in the options.",
      "  spherekit samples -o samples\n"
      "  spherekit samples -o big --members 8 --target-vertices 20000 --seed 7");
  cmd->add_option("-o,--output", args->output, "folder to write (created if missing)")->required();
  cmd->add_option("--members", args->options.members, "how many shapes")->check(CLI::Range(1, 1000))->capture_default_str();
  cmd->add_option("--target-vertices", args->options.target_vertices, "approximate vertex count per shape")
      ->check(CLI::Range(100, 10000000))->capture_default_str();
  cmd->add_option("--vertices", args->options.target_vertices)->check(CLI::Range(100, 10000000))->group("");
  cmd->add_option("--seed", args->options.seed, "seed of all shape and meshing randomness")->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "print no summary (errors still)");
  cmd->callback([args] { set_exit_code(run_samples(*args)); });
}

}  // namespace spherekit::cli
