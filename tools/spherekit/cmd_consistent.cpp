// `spherekit consistent`: the consistent parameterization of a collection (paper §3) into a
// collection folder; `spherekit add`: a new mesh mapped to an existing collection's feature
// locations (paper §5).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "cli_common.h"
#include "collection.h"
#include "commands.h"
#include "spherekit/sphere_param.h"
#include "sample_collection.h"
#include "spherekit/consistent_param.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/feature_io.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/version.h"

namespace fs = std::filesystem;

namespace spherekit::cli {
namespace {

Json map_entry_json(const ConstrainedParamResult& r) {
  Json j;
  j["efficiency"] = r.efficiency;
  j["l2_stretch"] = r.l2_stretch;
  j["linf_stretch"] = r.linf_stretch;
  j["flipped_faces"] = r.flipped_faces;
  j["winding"] = r.winding;
  j["max_feature_angle"] = r.max_feature_angle;
  j["holes_filled"] = r.holes_filled;
  j["method"] = r.map.provenance.method;
  j["network"] = feature_network_json(r.network);
  j["times"] = Json{{"network", r.times.network}, {"simplify", r.times.simplify},
                    {"refine", r.times.refine},   {"total", r.times.total}};
  return j;
}

// A map may enter a collection only if it is a bijection with every feature on its location.
Status require_exact(const ConstrainedParamResult& r, const std::string& label) {
  if (r.flipped_faces != 0)
    return Status(ErrorCode::SolverFailed,
                  strprintf("%s: the map has %d flipped faces (not bijective)", label.c_str(), r.flipped_faces));
  if (!(r.max_feature_angle < 1e-9))
    return Status(ErrorCode::Internal,
                  strprintf("%s: a feature is %.3g rad off its location", label.c_str(), r.max_feature_angle));
  return Status();
}

// Feature vertices of `mesh_path` in the order of `names`, from its landmark file.
Result<std::vector<int>> features_in_order(const std::string& lm_path, int vertices,
                                           const std::vector<std::string>& names) {
  auto lms = formats::read_landmarks(lm_path, vertices);
  if (!lms.ok()) return with_file(lms.status(), lm_path);
  std::vector<int> fv;
  for (const std::string& name : names) {
    auto it = std::find_if(lms->begin(), lms->end(), [&](const Landmark& l) { return l.name == name; });
    if (it == lms->end())
      return Status(ErrorCode::InvalidInput, strprintf("%s: no feature '%s' (the collection needs every one of its %zu features)",
                                                       lm_path.c_str(), name.c_str(), names.size()));
    fv.push_back(it->vertex);
  }
  return fv;
}

std::string default_features_path(const std::string& mesh) {
  const fs::path p(mesh);
  return (p.parent_path() / (p.stem().string() + ".lm.txt")).string();
}

std::string absolute_path(const std::string& p) {
  std::error_code ec;
  return fs::weakly_canonical(fs::absolute(p, ec), ec).string();
}

// ---------------------------------------------------------------------------------------
// consistent

struct ConsistentArgs {
  std::vector<std::string> meshes;
  std::vector<std::string> features;
  std::string output;
  std::string reference;
  std::string report;
  int remesh_size = 65;
  bool no_refine = false;
  bool quiet = false;
  SphereParamOptions sphere;
  ConstrainedFlags flags;
};

struct Member {
  std::string name, source, features_file;
  TriMesh mesh;
  std::vector<int> fv;
};

int run_consistent(const ConsistentArgs& a) {
  Stopwatch wall;
  if (Status s = require_collection_target(a.output); !s.ok()) return print_error(s);
  if (Status s = require_output_folders({a.report}); !s.ok()) return print_error(s);
  if (!a.features.empty() && a.features.size() != a.meshes.size())
    return print_error(Status(ErrorCode::InvalidArgument,
                              strprintf("%zu meshes but %zu --features files (give one per mesh, in order, or none)",
                                        a.meshes.size(), a.features.size())));

  // Members: the given meshes with their feature files, or the built-in samples.
  std::vector<Member> members;
  std::vector<std::string> names;  // feature names, in the first member's order
  if (a.meshes.empty()) {
    auto samples = samples::make_sample_collection();
    if (!samples.ok()) return print_error(samples.status());
    for (const auto& s : samples.value()) {
      Member m;
      m.name = s.name;
      m.source = "builtin:" + s.name;
      m.features_file = "builtin";
      m.mesh = s.mesh;
      if (names.empty())
        for (const Landmark& l : s.landmarks) names.push_back(l.name);
      for (const Landmark& l : s.landmarks) m.fv.push_back(l.vertex);
      members.push_back(std::move(m));
    }
  } else {
    std::set<std::string> stems;
    for (size_t i = 0; i < a.meshes.size(); ++i) {
      const std::string& path = a.meshes[i];
      Member m;
      m.name = file_stem(path);
      if (!stems.insert(m.name).second)
        return print_error(Status(ErrorCode::InvalidArgument,
                                  path + ": another input has the same file name stem '" + m.name +
                                      "' (sphere maps are named after it)"));
      auto loaded = load_mesh_checked(path, /*allow_boundary=*/true, /*repair=*/false);
      if (!loaded.ok()) return print_error(loaded.status());
      m.mesh = std::move(loaded->mesh);
      m.source = absolute_path(path);
      m.features_file = a.features.empty() ? default_features_path(path) : a.features[i];
      if (names.empty()) {
        auto lms = formats::read_landmarks(m.features_file, static_cast<int>(m.mesh.V.rows()));
        if (!lms.ok()) return print_error(with_file(lms.status(), m.features_file));
        if (lms->empty())
          return print_error(Status(ErrorCode::InvalidInput, m.features_file + ": no features"));
        for (const Landmark& l : lms.value()) names.push_back(l.name);
      }
      auto fv = features_in_order(m.features_file, static_cast<int>(m.mesh.V.rows()), names);
      if (!fv.ok()) return print_error(fv.status());
      // Extra features of later members would be silently ignored: refuse them instead.
      auto all = formats::read_landmarks(m.features_file, static_cast<int>(m.mesh.V.rows()));
      if (all.ok() && all->size() != names.size())
        return print_error(Status(ErrorCode::InvalidInput,
                                  strprintf("%s: has %zu features, %s has %zu (feature files must name the same features)",
                                            m.features_file.c_str(), all->size(), members.empty() ? "it" : members[0].features_file.c_str(),
                                            names.size())));
      m.fv = std::move(fv).value();
      members.push_back(std::move(m));
    }
  }

  int reference = 0;
  if (!a.reference.empty()) {
    reference = -1;
    for (size_t i = 0; i < members.size(); ++i)
      if (members[i].name == a.reference || a.reference == std::to_string(i)) reference = static_cast<int>(i);
    if (reference < 0)
      return print_error(Status(ErrorCode::InvalidArgument, "--reference '" + a.reference +
                                                                "' is neither a mesh's file stem nor an index"));
  }

  ConsistentParamOptions o;
  o.constrained = a.flags.resolve(a.sphere);
  o.reference = reference;
  o.remesh_size = a.remesh_size;
  o.refine_locations = !a.no_refine;
  o.threads = a.sphere.threads;
  std::vector<TriMesh> meshes;
  std::vector<std::vector<int>> features;
  for (const Member& m : members) {
    meshes.push_back(m.mesh);
    features.push_back(m.fv);
  }
  if (!a.quiet)
    std::fprintf(stderr, "consistent parameterization of %zu meshes, %zu features, reference %s\n", members.size(),
                 names.size(), members[static_cast<size_t>(reference)].name.c_str());

  ProgressRenderer progress(a.quiet);
  Result<ConsistentParamResult> result = [&] {
    ComputeScope graceful_cancel;
    return parameterize_consistent(meshes, features, o, progress.callback());
  }();
  progress.finish();
  if (cancel_requested()) return print_error(cancelled_status());
  if (!result.ok()) {
    // "mesh 2: ..." -> the file.
    Status s = result.status();
    for (size_t i = 0; i < members.size(); ++i) {
      const std::string tag = "mesh " + std::to_string(i) + ": ";
      if (s.message().rfind(tag, 0) == 0)
        s = Status(s.code(), members[i].source + ": " + s.message().substr(tag.size()));
    }
    return print_error(s);
  }
  const ConsistentParamResult& r = result.value();
  for (size_t i = 0; i < members.size(); ++i)
    if (Status s = require_exact(r.maps[i], members[i].source); !s.ok() && !(static_cast<int>(i) == reference && !o.refine_locations))
      return print_error(s);

  // The manifest.
  Json man;
  man["format"] = kCollectionFormat;
  man["format_version"] = kCollectionFormatVersion;
  man["library_version"] = kVersion;
  man["method"] = o.refine_locations ? "consistent (steps 1-6)" : "consistent (steps 1-2: reference locations)";
  man["reference"] = members[static_cast<size_t>(reference)].name;
  man["features"] = Json::array();
  for (size_t k = 0; k < names.size(); ++k) {
    const auto& p = r.final_locations[k];
    const auto& q = r.initial_locations[k];
    man["features"].push_back(Json{{"name", names[k]},
                                   {"location", Json::array({p.x(), p.y(), p.z()})},
                                   {"initial_location", Json::array({q.x(), q.y(), q.z()})}});
  }
  man["meshes"] = Json::array();
  for (size_t i = 0; i < members.size(); ++i) {
    const Member& m = members[i];
    Json e;
    e["name"] = m.name;
    e["source"] = m.source;
    e["features_file"] = m.features_file == "builtin" ? m.features_file : absolute_path(m.features_file);
    e["map"] = m.name + ".sphere.obj";
    e["vertices"] = static_cast<int>(m.mesh.V.rows());
    e["faces"] = static_cast<int>(m.mesh.F.rows());
    e["feature_vertices"] = m.fv;
    e["added"] = false;
    e["result"] = map_entry_json(r.maps[i]);
    man["meshes"].push_back(e);
  }
  man["options"] = constrained_options_json(o.constrained);
  man["options"]["remesh_size"] = o.remesh_size;
  man["options"]["refine_locations"] = o.refine_locations;
  if (!r.refinement_failure.empty()) {
    // Which mesh: "mesh 2: ..." -> its name.
    std::string why = r.refinement_failure;
    for (size_t i = 0; i < members.size(); ++i) {
      const std::string tag = "mesh " + std::to_string(i) + ": ";
      if (why.rfind(tag, 0) == 0) why = members[i].name + ": " + why.substr(tag.size());
    }
    man["method"] = "consistent (steps 1-2: reference locations; step 6 failed)";
    man["refinement_failure"] = why;
    Json rejected = Json::array();
    for (const auto& p : r.rejected_locations) rejected.push_back(Json::array({p.x(), p.y(), p.z()}));
    man["rejected_locations"] = rejected;
    std::fprintf(stderr, "spherekit: warning: step 6 failed (%s); the collection keeps the step-2 maps (locations from the reference)\n",
                 why.c_str());
  }
  man["steps"] = Json{{"reference_efficiency", r.reference_efficiency},
                      {"joint_efficiency", r.joint_efficiency},
                      {"joint_flipped_faces", r.joint_flips},
                      {"remesh_vertices", r.remesh_vertices}};
  man["times"] = Json{{"step1_reference", r.times.reference}, {"step2_initial_maps", r.times.initial},
                      {"step3_remesh", r.times.remesh},       {"step4_concatenate", r.times.concatenate},
                      {"step5_joint_map", r.times.joint},     {"step6_final_maps", r.times.final_maps},
                      {"total", r.times.total}};

  Status written = write_collection_folder(a.output, [&](const std::string& dir) -> Status {
    for (size_t i = 0; i < members.size(); ++i)
      SPHEREKIT_RETURN_IF_ERROR(formats::write_sphere_map((fs::path(dir) / (members[i].name + ".sphere.obj")).string(),
                                                          members[i].mesh, r.maps[i].map));
    SPHEREKIT_RETURN_IF_ERROR(
        formats::write_file_atomic((fs::path(dir) / "features.txt").string(), sphere_points_text(names, r.final_locations)));
    return write_json_atomic((fs::path(dir) / kCollectionManifest).string(), man);
  });
  if (!written.ok()) return print_error(written);

  const double wall_seconds = wall.seconds();
  if (!a.report.empty()) {
    Json rep = man;
    rep["output"] = a.output;
    rep["times"]["wall"] = wall_seconds;
    rep["cpu_seconds"] = cpu_seconds();
    rep["peak_rss_mb"] = peak_rss_mb();
    if (Status s = write_json_atomic(a.report, rep); !s.ok()) return print_error(s);
  }
  if (!a.quiet) {
    std::printf("collection %s: %zu meshes, %zu features (%s)\n", a.output.c_str(), members.size(), names.size(),
                o.refine_locations && r.refinement_failure.empty() ? "locations from all meshes"
                                                                   : "locations from the reference only");
    Table steps({"step", "work", "time (s)"});
    steps.add_row({"1", "unconstrained map of " + members[static_cast<size_t>(reference)].name,
                   strprintf("%.2f", r.times.reference)});
    steps.add_row({"2", strprintf("constrained maps of %zu meshes to F'", members.size() - 1),
                   strprintf("%.2f", r.times.initial)});
    if (o.refine_locations && members.size() > 1) {
      steps.add_row({"3", strprintf("remesh %d x %d, features snapped", o.remesh_size, o.remesh_size),
                     strprintf("%.2f", r.times.remesh)});
      steps.add_row({"4", strprintf("concatenate: %d vertices in R^%zu", r.remesh_vertices, 3 * members.size()),
                     strprintf("%.2f", r.times.concatenate)});
      steps.add_row({"5", strprintf("joint unconstrained map (efficiency %.4f)", r.joint_efficiency),
                     strprintf("%.2f", r.times.joint)});
      steps.add_row({"6", strprintf("constrained maps of %zu meshes to F", members.size()),
                     strprintf("%.2f", r.times.final_maps)});
    }
    steps.add_row({"", "total", strprintf("%.2f", r.times.total)});
    steps.print();
    std::printf("\n");
    Table t({"mesh", "V", "efficiency", "flips", "feature err (rad)", "paths", "path len", "max len/geo", "Steiner",
             "time (s)"});
    for (size_t i = 0; i < members.size(); ++i) {
      const auto& m = r.maps[i];
      t.add_row({members[i].name, std::to_string(members[i].mesh.V.rows()), strprintf("%.4f", m.efficiency),
                 std::to_string(m.flipped_faces), strprintf("%.1e", m.max_feature_angle),
                 std::to_string(m.network.paths), strprintf("%.4g", m.network.total_length),
                 strprintf("%.2f", m.network.max_ratio), std::to_string(m.network.steiner_vertices),
                 strprintf("%.2f", m.times.total)});
    }
    t.print();
    std::printf("wall %.2f s, CPU %.2f s, peak memory %.0f MB\n", wall_seconds, cpu_seconds(), peak_rss_mb());
  }
  return 0;
}

// ---------------------------------------------------------------------------------------
// add

struct AddArgs {
  std::string dir;
  std::string mesh;
  std::string features;
  std::string name;
  bool replace = false;
  bool quiet = false;
  SphereParamOptions sphere;
  ConstrainedFlags flags;
};

int run_add(const AddArgs& a) {
  Stopwatch wall;
  auto col = read_collection(a.dir);
  if (!col.ok()) return print_error(col.status());
  CollectionInfo& c = col.value();
  auto loaded = load_mesh_checked(a.mesh, /*allow_boundary=*/true, /*repair=*/false);
  if (!loaded.ok()) return print_error(loaded.status());
  const std::string name = a.name.empty() ? file_stem(a.mesh) : a.name;
  // The map is written as DIR/<name>.sphere.obj: a name with a path would put it elsewhere
  // (and make the manifest unreadable, see read_collection).
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos)
    return print_error(Status(ErrorCode::InvalidArgument, "--name '" + name + "': must be a plain file name"));
  int existing = -1, i = 0;
  for (const Json& e : c.manifest["meshes"]) {
    if (e["name"].get<std::string>() == name) existing = i;
    ++i;
  }
  if (existing >= 0 && !a.replace)
    return print_error(Status(ErrorCode::InvalidArgument, a.mesh + ": the collection already has a mesh named '" + name +
                                                              "' (use --name, or --replace to map it again)"));
  // Never grow a broken collection: every other member's map must be there and fit.
  if (Status s = check_member_maps(c, existing); !s.ok()) return print_error(s);
  const std::string lm = a.features.empty() ? default_features_path(a.mesh) : a.features;
  auto fv = features_in_order(lm, loaded->check.vertices, c.feature_names);
  if (!fv.ok()) return print_error(fv.status());

  ConstrainedParamOptions o = a.flags.resolve(a.sphere);
  if (c.manifest.contains("options") && c.manifest["options"].is_object()) {
    // The collection's shape-defining settings, unless given here.
    const Json& opt = c.manifest["options"];
    if (opt.contains("seed") && opt["seed"].is_number_unsigned() && a.sphere.seed == SphereParamOptions{}.seed)
      o.sphere.seed = opt["seed"].get<std::uint64_t>();
  }
  ProgressRenderer progress(a.quiet, name);
  Result<ConstrainedParamResult> result = [&] {
    ComputeScope graceful_cancel;
    return parameterize_sphere_constrained(loaded->mesh, fv.value(), c.locations, o, progress.callback());
  }();
  progress.finish();
  if (cancel_requested()) return print_error(cancelled_status());
  if (!result.ok()) return print_error(with_file(result.status(), a.mesh));
  const ConstrainedParamResult& r = result.value();
  if (Status s = require_exact(r, a.mesh); !s.ok()) return print_error(s);

  Json e;
  e["name"] = name;
  e["source"] = absolute_path(a.mesh);
  e["features_file"] = absolute_path(lm);
  e["map"] = name + ".sphere.obj";
  e["vertices"] = loaded->check.vertices;
  e["faces"] = loaded->check.faces;
  e["feature_vertices"] = fv.value();
  e["added"] = true;
  e["result"] = map_entry_json(r);
  Json man = c.manifest;
  if (existing >= 0)
    man["meshes"][static_cast<size_t>(existing)] = e;
  else
    man["meshes"].push_back(e);
  // The map first, then the manifest that names it: a reader never sees a member without
  // its map. If the manifest cannot be written, the new map is removed again.
  const std::string map_path = (fs::path(a.dir) / (name + ".sphere.obj")).string();
  const bool map_existed = fs::exists(map_path);
  // --replace: the old map goes back if the manifest cannot be written, so that the folder
  // stays as it was (the manifest still describes the old map).
  std::string old_map;
  if (map_existed) {
    auto bytes = formats::read_file(map_path);
    if (!bytes.ok()) return print_error(bytes.status());
    old_map = std::move(bytes).value();
  }
  if (Status s = formats::write_sphere_map(map_path, loaded->mesh, r.map); !s.ok()) return print_error(s);
  if (Status s = write_json_atomic((fs::path(a.dir) / kCollectionManifest).string(), man); !s.ok()) {
    std::error_code ec;
    if (map_existed)
      (void)formats::write_file_atomic(map_path, old_map);
    else
      fs::remove(map_path, ec);
    return print_error(s);
  }
  if (!a.quiet) {
    std::printf("%s -> %s (%zu features on the collection's locations)\n", a.mesh.c_str(), map_path.c_str(),
                c.feature_names.size());
    std::printf("  efficiency %.4f, flipped faces %d, max feature error %.2g rad, %d paths, %d Steiner vertices\n",
                r.efficiency, r.flipped_faces, r.max_feature_angle, r.network.paths, r.network.steiner_vertices);
    std::printf("  time %.2f s (wall %.2f s), peak memory %.0f MB\n", r.times.total, wall.seconds(), peak_rss_mb());
  }
  return 0;
}

}  // namespace

int run_consistent_job(const std::vector<std::string>& meshes, const std::string& output, const std::string& report,
                       bool quiet, const SphereParamOptions& sphere) {
  ConsistentArgs a;
  a.meshes = meshes;
  a.output = output;
  a.report = report;
  a.quiet = quiet;
  a.sphere = sphere;
  return run_consistent(a);
}

void register_consistent(CLI::App& app) {
  auto args = std::make_shared<ConsistentArgs>();
  CLI::App* cmd = add_command(
      app, "consistent", "Map a collection of meshes consistently onto one sphere (features coincide)",
      "Consistent spherical parameterization (Asirvatham, Praun, Hoppe 2005): every mesh is mapped\n"
      "bijectively onto the unit sphere so that corresponding features (same names in the meshes'\n"
      "feature files, `name vertex` lines) land on the same sphere points. Then two surface points\n"
      "correspond when their sphere points are equal ('spherekit correspond').\n"
      "Steps: 1 unconstrained map of the reference (its features give F'); 2 constrained maps of\n"
      "the others to F'; 3 remesh all as octahedral geometry images, features snapped; 4 one mesh\n"
      "in R^3n; 5 its unconstrained map (n-D quadric, summed stretch) gives the final locations F;\n"
      "6 constrained maps of all meshes to F. --no-refine stops after step 2.\n"
      "Writes the folder -o DIR: collection.json (manifest), features.txt (`name x y z`: F) and\n"
      "<stem>.sphere.obj per mesh; DIR is replaced only when everything succeeded. Feature files\n"
      "default to NAME.lm.txt beside each mesh. Without meshes, the built-in sample collection.",
      "  spherekit consistent -o cats cat0.obj cat2.obj cat5.obj cat9.obj\n"
      "  spherekit consistent -o pair bunny.obj gargoyle.obj --features bunny.lm.txt gargoyle.lm.txt\n"
      "  spherekit consistent -o samples-collection          # the built-in samples");
  cmd->add_option("MESH", args->meshes, "input meshes (genus 0, holes allowed)");
  cmd->add_option("-o,--output", args->output, "collection folder to write")->required();
  cmd->add_option("--features", args->features, "feature files, one per mesh in order (default: MESH stem + .lm.txt)");
  cmd->add_option("--reference", args->reference, "mesh giving the initial locations (file stem or index; default the first)");
  cmd->add_option("--remesh-size", args->remesh_size, "step 3 grid side (2^k+1)")
      ->capture_default_str()
      ->check(CLI::IsMember({9, 17, 33, 65, 129, 257, 513}));
  cmd->add_flag("--no-refine", args->no_refine, "stop after step 2 (locations from the reference alone)");
  cmd->add_option("--report", args->report, "also write a JSON report here");
  cmd->add_flag("-q,--quiet", args->quiet, "print neither progress nor the summary (errors still)");
  add_sphere_param_options(*cmd, args->sphere);
  add_constrained_flags(*cmd, args->flags);
  cmd->callback([args] { set_exit_code(run_consistent(*args)); });

  auto add_args = std::make_shared<AddArgs>();
  CLI::App* add = add_command(
      app, "add", "Map a new mesh into an existing collection (its features on the collection's)",
      "Constrained spherical parameterization of MESH with its features exactly on the collection's\n"
      "feature locations F (the paper's way to grow a database without recomputing it, §5). The\n"
      "feature file (default NAME.lm.txt beside the mesh) must name every feature of the\n"
      "collection. Writes DIR/<stem>.sphere.obj and updates collection.json.",
      "  spherekit add cats cat10.obj\n"
      "  spherekit add cats scan.ply --features scan.lm.txt --name cat_scan");
  add->add_option("DIR", add_args->dir, "collection folder")->required();
  add->add_option("MESH", add_args->mesh, "mesh to add")->required();
  add->add_option("--features", add_args->features, "its feature file (default: MESH stem + .lm.txt)");
  add->add_option("--name", add_args->name, "member name (default: the mesh's file stem)");
  add->add_flag("--replace", add_args->replace, "map again if the collection has a member of that name");
  add->add_flag("-q,--quiet", add_args->quiet, "print neither progress nor the summary (errors still)");
  add_sphere_param_options(*add, add_args->sphere);
  add_constrained_flags(*add, add_args->flags);
  add->callback([add_args] { set_exit_code(run_add(*add_args)); });
}

}  // namespace spherekit::cli
