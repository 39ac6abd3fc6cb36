// `spherekit check`: the structural report of meshes (check_mesh) and the verdict the
// parameterizer would give (require_param_accepts); --repair is pipeline::repair_mesh.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/check_mesh.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/mesh_io.h"
#include "spherekit/propose_landmarks.h"

namespace spherekit::cli {
namespace {

struct CheckArgs {
  std::vector<std::string> meshes;
  bool json = false;
  bool repair = false;
  std::string output;
  std::vector<std::string> landmarks;  ///< none, or one per mesh
};

// Several meshes with one landmark file each: the files correspond (the first file's names
// in every file) and no landmark is most likely on another feature (suspect_landmarks against
// the first mesh). Warnings are printed; a missing name is an error. Returns the per-mesh
// suspect names (for --json) or the error.
Result<std::vector<std::vector<std::string>>> check_correspondence(const std::vector<std::string>& files,
                                                                  const std::vector<TriMesh>& meshes,
                                                                  const std::vector<std::vector<Landmark>>& lms) {
  std::vector<std::vector<int>> order(lms.size());
  for (std::size_t i = 0; i < lms.size(); ++i)
    for (const Landmark& first : lms[0]) {
      auto it = std::find_if(lms[i].begin(), lms[i].end(), [&](const Landmark& l) { return l.name == first.name; });
      if (it == lms[i].end())
        return Status(ErrorCode::InvalidInput, files[i] + ": no landmark '" + first.name + "' (" + files[0] + " has it)");
      order[i].push_back(it->vertex);
    }
  auto suspects = suspect_landmarks(meshes, order, 0);
  if (!suspects.ok()) return suspects.status();
  std::vector<std::vector<std::string>> out(lms.size());
  for (const SuspectLandmark& x : *suspects) {
    const std::string& name = lms[0][static_cast<std::size_t>(x.landmark)].name;
    out[static_cast<std::size_t>(x.member)].push_back(name);
    std::fprintf(stderr,
                 "spherekit: warning: %s: landmark '%s' is not where %s's is: its distances to the others differ by a "
                 "factor %.2f (the other landmarks: %.2f); misplaced, or on another feature?\n",
                 files[static_cast<std::size_t>(x.member)].c_str(), name.c_str(), files[0].c_str(), std::exp(x.disagreement),
                 std::exp(x.typical));
  }
  return out;
}

int run_check(const CheckArgs& args) {
  if (args.repair && args.meshes.size() != 1)
    return print_error(Status(ErrorCode::InvalidArgument, "--repair takes exactly one MESH"));
  if (!args.landmarks.empty() && args.landmarks.size() != args.meshes.size())
    return print_error(Status(ErrorCode::InvalidArgument, "give one --landmarks file per MESH, in order"));
  if (args.repair) {
    if (Status s = require_output_folders({args.output}); !s.ok()) return print_error(s);
  }

  int worst = 0;
  Json report = Json::array();
  // For the correspondence check across files (all of them read, every landmark file valid).
  std::vector<TriMesh> meshes;
  std::vector<std::vector<Landmark>> all_landmarks;
  std::vector<int> json_index;
  bool all_read = true;
  for (std::size_t mi = 0; mi < args.meshes.size(); ++mi) {
    const std::string& path = args.meshes[mi];
    const std::string lm_file = args.landmarks.empty() ? std::string() : args.landmarks[mi];
    auto loaded = load_mesh(path);
    if (!loaded.ok()) {
      worst = worse_exit_code(worst, print_error(loaded.status()));
      if (args.json)
        report.push_back(Json{{"file", path},
                              {"error", loaded.status().message()},
                              {"error_code", error_code_name(loaded.status().code())}});
      all_read = false;
      continue;
    }
    LoadedMesh& m = loaded.value();
    // Landmarks index the vertices of the file as read (before --repair appends any).
    Result<std::vector<Landmark>> landmarks = std::vector<Landmark>{};
    if (!lm_file.empty()) landmarks = formats::read_landmarks(lm_file, m.check.vertices);

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
      if (!lm_file.empty()) {
        if (landmarks.ok())
          j["landmarks"] = Json{{"file", lm_file}, {"count", landmarks->size()}};
        else
          j["landmarks"] = Json{{"file", lm_file}, {"error", landmarks.status().message()}};
      }
      json_index.push_back(static_cast<int>(report.size()));
      report.push_back(std::move(j));
    } else {
      print_check_summary(m, verdict);
      if (args.repair)
        std::printf("  repair: removed %d unreferenced vert%s, split %d pinched vertex fan%s; wrote %s%s\n",
                    repair.removed_unreferenced_vertices, repair.removed_unreferenced_vertices == 1 ? "ex" : "ices",
                    repair.split_vertices, repair.split_vertices == 1 ? "" : "s", args.output.c_str(),
                    repair.renumbered ? " (vertex numbers changed: landmark files of the input need remapping)" : "");
      if (!lm_file.empty() && landmarks.ok())
        std::printf("  landmarks: %zu in %s, all valid\n", landmarks->size(), lm_file.c_str());
    }
    if (!verdict.ok()) worst = worse_exit_code(worst, print_error(verdict));
    if (!landmarks.ok()) worst = worse_exit_code(worst, print_error(landmarks.status()));
    all_read = all_read && landmarks.ok() && verdict.ok();
    if (!lm_file.empty() && landmarks.ok()) {
      meshes.push_back(m.mesh);
      all_landmarks.push_back(*landmarks);
    }
  }
  // A warning does not change the exit code: the files are valid, only their correspondence is
  // in doubt (left/right swaps of a symmetric pair are not seen).
  if (args.landmarks.size() > 1 && all_read) {
    auto suspects = check_correspondence(args.landmarks, meshes, all_landmarks);
    if (!suspects.ok()) {
      worst = worse_exit_code(worst, print_error(suspects.status()));
    } else if (args.json) {
      for (std::size_t i = 0; i < json_index.size(); ++i)
        report[static_cast<std::size_t>(json_index[i])]["landmarks"]["suspect"] = (*suspects)[i];
    } else {
      std::size_t n = 0;
      for (const auto& v : *suspects) n += v.size();
      std::printf("landmarks: %zu files correspond by name; %s\n", args.landmarks.size(),
                  n == 0 ? "every landmark's distances to the others agree with the first file's"
                         : (std::to_string(n) + " most likely misplaced (warnings above)").c_str());
    }
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
      "indices in range, names and vertices unique); with several meshes, one file each, in order:\n"
      "every file must have the first file's names, and a landmark whose geodesic distances to the\n"
      "others differ from the first mesh's far beyond the other landmarks' is reported as most\n"
      "likely misplaced (a warning, the exit code unchanged; as `consistent` does before mapping).",
      "  spherekit check spot.obj bunny.obj\n"
      "  spherekit check --json meshes/*.obj > checks.json\n"
      "  spherekit check cow.obj --repair -o cow_fixed.obj\n"
      "  spherekit check cat.obj --landmarks cat.lm.txt\n"
      "  spherekit check cat0.obj cat2.obj --landmarks cat0.lm.txt cat2.lm.txt");
  cmd->add_option("MESH", args->meshes, "mesh files (.obj .ply .off .stl .gltf .glb)")->required();
  cmd->add_flag("--json", args->json, "print a JSON array with one object per mesh instead of text");
  CLI::Option* repair = cmd->add_flag("--repair", args->repair, "drop unreferenced vertices and split non-manifold (pinched) ones; needs -o");
  CLI::Option* output = cmd->add_option("-o,--output", args->output, "where --repair writes the repaired mesh (.obj/.ply)");
  repair->needs(output);
  output->needs(repair);
  cmd->add_option("--landmarks", args->landmarks,
                  "also validate landmark files (name vertex_index), one per MESH; several: also their correspondence");
  cmd->callback([args] { set_exit_code(run_check(*args)); });
}

}  // namespace spherekit::cli
