// `spherekit check`: the structural report of meshes (check_mesh) and the verdict the
// parameterizer would give (require_param_accepts); --repair is pipeline::repair_mesh.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/check_mesh.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"

namespace spherekit::cli {
namespace {

struct CheckArgs {
  std::vector<std::string> meshes;
  bool json = false;
  bool repair = false;
  std::string output;
  std::string landmarks;
};

int run_check(const CheckArgs& args) {
  if (args.repair && args.meshes.size() != 1)
    return print_error(Status(ErrorCode::InvalidArgument, "--repair takes exactly one MESH"));
  if (!args.landmarks.empty() && args.meshes.size() != 1)
    return print_error(Status(ErrorCode::InvalidArgument, "--landmarks takes exactly one MESH"));
  if (args.repair) {
    if (Status s = require_output_folders({args.output}); !s.ok()) return print_error(s);
  }

  int worst = 0;
  Json report = Json::array();
  for (const std::string& path : args.meshes) {
    auto loaded = load_mesh(path);
    if (!loaded.ok()) {
      worst = worse_exit_code(worst, print_error(loaded.status()));
      if (args.json)
        report.push_back(Json{{"file", path},
                              {"error", loaded.status().message()},
                              {"error_code", error_code_name(loaded.status().code())}});
      continue;
    }
    LoadedMesh& m = loaded.value();
    // Landmarks index the vertices of the file as read (before --repair appends any).
    Result<std::vector<Landmark>> landmarks = std::vector<Landmark>{};
    if (!args.landmarks.empty()) landmarks = formats::read_landmarks(args.landmarks, m.check.vertices);

    pipeline::MeshRepair repair;
    if (args.repair) {
      repair = pipeline::repair_mesh(m);
      Status written = formats::write_mesh(args.output, m.mesh);
      if (!written.ok()) return print_error(written);
    }

    // Holes are accepted: the stages close them with removable faces.
    const Status verdict = param_verdict(m, /*allow_boundary=*/true);

    if (args.json) {
      Json j = mesh_check_json(path, m.check);
      j["source_faces"] = source_faces_json(m.info);
      if (!verdict.ok()) j["error"] = verdict.message();
      if (args.repair)
        j["repair"] = pipeline::mesh_repair_json(repair, args.output);
      if (!args.landmarks.empty()) {
        if (landmarks.ok())
          j["landmarks"] = Json{{"file", args.landmarks}, {"count", landmarks->size()}};
        else
          j["landmarks"] = Json{{"file", args.landmarks}, {"error", landmarks.status().message()}};
      }
      report.push_back(std::move(j));
    } else {
      print_check_summary(m, verdict);
      if (args.repair)
        std::printf("  repair: removed %d unreferenced vert%s, split %d pinched vertex fan%s; wrote %s%s\n",
                    repair.removed_unreferenced_vertices, repair.removed_unreferenced_vertices == 1 ? "ex" : "ices",
                    repair.split_vertices, repair.split_vertices == 1 ? "" : "s", args.output.c_str(),
                    repair.renumbered ? " (vertex numbers changed: landmark files of the input need remapping)" : "");
      if (!args.landmarks.empty() && landmarks.ok())
        std::printf("  landmarks: %zu in %s, all valid\n", landmarks->size(), args.landmarks.c_str());
    }
    if (!verdict.ok()) worst = worse_exit_code(worst, print_error(verdict));
    if (!landmarks.ok()) worst = worse_exit_code(worst, print_error(landmarks.status()));
  }
  if (args.json) std::printf("%s\n", report.dump(2).c_str());
  return worst;
}

}  // namespace

void register_check(CLI::App& app) {
  auto args = std::make_shared<CheckArgs>();
  CLI::App* cmd = add_command(
      app, "check", "Report the structure of meshes and whether param accepts them",
      "Read meshes and report their structure: vertices, faces, edges, components, boundary loops\n"
      "(holes), non-manifold edges and pinched vertices, degenerate/duplicate/zero-area faces,\n"
      "non-finite coordinates, Euler characteristic and genus, and whether `param` accepts the mesh\n"
      "(one manifold, oriented, genus-0 component; holes allowed). Exit code: 0 if every mesh is\n"
      "accepted, 3 if a mesh is malformed or not accepted, 4 if a file cannot be read (the worst\n"
      "over all files). --repair drops vertices no face uses and splits pinched vertices (one copy per\n"
      "face fan) and writes the result to -o, whatever the verdict (dropping renumbers the vertices:\n"
      "landmark files of the input no longer fit). Polygon faces are triangulated on reading; the\n"
      "report counts the file's triangles, quads and n-gons (--json: face_polygon, triangle -> face).\n"
      "--landmarks also validates a landmark file against the mesh (lines 'name vertex_index':\n"
      "indices in range, names and vertices unique).",
      "  spherekit check spot.obj bunny.obj\n"
      "  spherekit check --json meshes/*.obj > checks.json\n"
      "  spherekit check cow.obj --repair -o cow_fixed.obj\n"
      "  spherekit check cat.obj --landmarks cat.lm.txt");
  cmd->add_option("MESH", args->meshes, "mesh files (.obj .ply .off .stl .gltf .glb)")->required();
  cmd->add_flag("--json", args->json, "print a JSON array with one object per mesh instead of text");
  CLI::Option* repair = cmd->add_flag("--repair", args->repair, "drop unreferenced vertices and split non-manifold (pinched) ones; needs -o");
  CLI::Option* output = cmd->add_option("-o,--output", args->output, "where --repair writes the repaired mesh (.obj/.ply)");
  repair->needs(output);
  output->needs(repair);
  cmd->add_option("--landmarks", args->landmarks, "also validate this landmark file (name vertex_index) against MESH");
  cmd->callback([args] { set_exit_code(run_check(*args)); });
}

}  // namespace spherekit::cli
