// `spherekit run`: the main job. Checks, parameterizes and evaluates every input mesh (the
// built-in samples when none is given), writes the sphere maps and one report.json into an
// output folder, builds each map's 129 x 129 octahedral geometry image (as `convert`) with its
// remesh PSNR, previews and glTF levels of detail, and prints a summary table. A failing mesh
// is reported and skipped; the others still run. A collection (the samples, or meshes with
// feature files) is then mapped consistently, converted and used by the applications
// (run_collection.cpp), and everything is shown on OUT/index.html (site_page.h).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_common.h"
#include "commands.h"
#include "convert_common.h"
#include "run_job.h"
#include "site_page.h"
#include "sample_collection.h"
#include "spherekit/convert/geometry_image_exr.h"
#include "spherekit/convert/gltf_lods.h"
#include "spherekit/correspondence.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/geometry_image.h"
#include "spherekit/metrics.h"
#include "spherekit/sphere_param.h"
#include "spherekit/version.h"

namespace fs = std::filesystem;

namespace spherekit::cli {
namespace {

// glTF levels of detail per mesh from that image (129, 65, 33), for the page's 3-D view.
constexpr int kGeometryImageLods = 3;


struct RunArgs {
  std::vector<std::string> meshes;
  std::string output = "spherekit-out";
  bool quiet = false;
  SphereParamOptions options;
};

// Output name for a mesh: its stem, made unique when two inputs share one (a/x.obj, b/x.ply).
std::string unique_stem(const std::string& path, std::set<std::string>& used) {
  const std::string stem = file_stem(path);
  std::string name = stem;
  for (int k = 2; !used.insert(name).second; ++k) name = stem + "_" + std::to_string(k);
  return name;
}

struct MeshOutcome {
  Json json;                       // the report entry
  std::vector<std::string> row;    // the summary-table row
  Json model;                      // the results page's model (site_page.h), when made
  int exit_code = 0;
};

MeshOutcome run_one(const RunArgs& a, const std::string& path, const std::string& name, const fs::path& out_dir) {
  MeshOutcome out;
  Stopwatch wall;
  out.json["file"] = path;
  out.json["name"] = name;
  auto fail = [&](const Status& status) {
    out.exit_code = print_error(status);
    out.json["status"] = "failed";
    out.json["error"] = status.message();
    out.json["error_code"] = error_code_name(status.code());
    out.json["times"]["wall"] = wall.seconds();
    out.row = {name, "", "", "", "", "", "", "", "", strprintf("%.2f", wall.seconds()),
               std::string("FAILED: ") + error_code_name(status.code())};
    return out;
  };

  auto loaded = load_mesh_checked(path, /*allow_boundary=*/true, /*repair=*/false);
  if (!loaded.ok()) {
    // Still record what the check saw, when the file could be read at all.
    if (auto plain = load_mesh(path); plain.ok()) out.json["check"] = mesh_check_json(path, plain->check);
    return fail(loaded.status());
  }
  const LoadedMesh& m = loaded.value();
  out.json["check"] = mesh_check_json(path, m.check);

  ProgressRenderer progress(a.quiet, name);
  Stopwatch param_time;
  Result<SphereParamResult> result = [&] {
    ComputeScope graceful_cancel;
    return parameterize_sphere(m.mesh, a.options, progress.callback());
  }();
  progress.finish();
  const double param_seconds = param_time.seconds();
  if (!result.ok()) return fail(with_file(result.status(), path));
  const SphereParamResult& r = result.value();
  out.json["param"] = sphere_param_result_json(r);
  if (r.flipped_faces != 0)
    return fail(Status(ErrorCode::SolverFailed, strprintf("%s: the map has %d flipped faces (not bijective); not written",
                                                          path.c_str(), r.flipped_faces)));

  const std::string sphere_path = (out_dir / (name + ".sphere.obj")).string();
  Stopwatch write_time;
  if (Status s = formats::write_sphere_map(sphere_path, m.mesh, r.map); !s.ok()) return fail(s);
  const double write_seconds = write_time.seconds();
  out.json["sphere_map"] = sphere_path;

  // Measure the written map independently of the optimizer's own bookkeeping, with the
  // evaluator's definitions (these are the numbers to compare with evalsphere.py).
  Stopwatch eval_time;
  auto metrics = evaluate_sphere_map(m.mesh, r.map.S);
  if (!metrics.ok()) return fail(with_file(metrics.status(), sphere_path));
  const SphereMapMetrics& e = metrics.value();
  out.json["eval"] = sphere_map_metrics_json(e, false);
  const double eval_seconds = eval_time.seconds();

  // The octahedral geometry image of the map and its remesh PSNR, exactly as `convert` does
  // it (faces spanning holes of the mesh are left out of the PSNR).
  const std::string gim_path = (out_dir / (name + ".gim" + std::to_string(kRunImageSize) + ".exr")).string();
  Stopwatch gim_time;
  const GeometryImageOptions gio = geometry_image_options(ConvertArgs{});  // convert's defaults
  auto sampled = sample_geometry_image(m.mesh, r.map.S, kRunImageSize, gio);
  if (!sampled.ok()) return fail(with_file(sampled.status(), path));
  const GeometryImage& image = sampled.value();
  const TriMesh remesh = geometry_image_mesh(image);
  if (Status s = convert::write_geometry_image_exr(gim_path, image, {path, sphere_path}); !s.ok()) return fail(s);
  const bool has_holes = image.texels_in_holes > 0;
  RemeshErrorOptions psnr_opts;
  psnr_opts.samples = kRunPsnrSamples;
  const RemeshError err = remesh_error(m.mesh, remesh, psnr_opts, geometry_image_hole_faces(image));
  // Previews and levels of detail (as `convert --lods`), for people and for the page.
  const std::string gim_prefix = gltf_prefix(gim_path);
  auto previews = write_geometry_image_previews(image, gim_prefix);
  if (!previews.ok()) return fail(previews.status());
  convert::GltfLodOptions lod_opts;
  lod_opts.levels = kGeometryImageLods;
  lod_opts.reference_rms_error = err.rms;
  lod_opts.name = name;
  lod_opts.provenance = {path, sphere_path};
  lod_opts.drop_hole_faces = true;
  auto level_images = convert::lod_geometry_images(m.mesh, r.map.S, image, kGeometryImageLods, gio);
  if (!level_images.ok()) return fail(with_file(level_images.status(), path));
  auto lods = convert::build_gltf_lods(level_images.value(), lod_opts);
  if (!lods.ok()) return fail(lods.status());
  auto lod_paths = convert::write_gltf_lods(gim_prefix, lods.value());
  if (!lod_paths.ok()) return fail(lod_paths.status());
  const double gim_seconds = gim_time.seconds();
  Json lod_files = Json::array(), page_lods = Json::array();
  for (const std::string& f : lod_paths->levels) {
    lod_files.push_back(f);
    page_lods.push_back(fs::path(f).filename().string());
  }
  out.json["geometry_image"] = Json{{"file", gim_path},
                                    {"size", kRunImageSize},
                                    {"psnr_db", number_or_null(err.psnr)},
                                    {"psnr_excludes_hole_faces", has_holes},
                                    {"previews", previews.value()},
                                    {"lods", lod_files},
                                    {"seconds", gim_seconds}};
  out.model = Json{{"name", name},
                   {"lods", page_lods},
                   {"images", Json::array({Json{{"label", "geometry image: normals"},
                                                {"png", fs::path(previews->at(0)).filename().string()}},
                                           Json{{"label", "geometry image: positions"},
                                                {"png", fs::path(previews->at(1)).filename().string()}}})}};

  out.json["status"] = "ok";
  out.json["times"] = Json{{"read", m.read_seconds},        {"check", m.check_seconds},
                           {"param", param_seconds},        {"write", write_seconds},
                           {"eval", eval_seconds},          {"geometry_image", gim_seconds},
                           {"wall", wall.seconds()}};
  out.row = {name,
             std::to_string(m.check.vertices),
             std::to_string(m.check.faces),
             std::to_string(m.check.boundary_loops),
             strprintf("%.4f", e.efficiency),
             strprintf("%.4g", e.linf),
             std::to_string(e.flipped),
             e.closed ? strprintf("%.4f", e.winding) : std::string("-"),
             strprintf("%.2f", err.psnr),
             strprintf("%.2f", wall.seconds()),
             "ok"};
  return out;
}

// Mean correspondence error of a collection of samples over all ordered pairs, from their
// .corr.txt ground truth (vertex lists, line k of every file the same point).
Json collection_correspondence_json(const std::vector<std::string>& meshes, const std::string& col_dir) {
  struct Member {
    TriMesh mesh;
    RowMat3d S;
    std::vector<int> corr;
  };
  std::vector<Member> m;
  for (const std::string& path : meshes) {
    auto loaded = load_mesh(path);
    if (!loaded.ok()) return Json{{"error", loaded.status().message()}};
    auto map = formats::read_sphere_map((fs::path(col_dir) / (file_stem(path) + ".sphere.obj")).string(), loaded->mesh);
    if (!map.ok()) return Json{{"error", map.status().message()}};
    auto text = formats::read_file((fs::path(path).parent_path() / (file_stem(path) + ".corr.txt")).string());
    if (!text.ok()) return Json{{"error", text.status().message()}};
    Member x{loaded->mesh, map->S, {}};
    std::istringstream in(text.value());
    for (int v; in >> v;) x.corr.push_back(v);
    m.push_back(std::move(x));
  }
  double mean = 0, u5 = 0, u10 = 0;
  int pairs = 0;
  Json rows = Json::array();
  for (size_t i = 0; i < m.size(); ++i)
    for (size_t j = 0; j < m.size(); ++j) {
      if (i == j || m[i].corr.size() != m[j].corr.size()) continue;
      std::vector<SurfacePoint> from;
      for (int v : m[i].corr) from.push_back(vertex_surface_point(m[i].mesh, v));
      auto moved = transfer_points(m[i].mesh, m[i].S, from, m[j].mesh, m[j].S);
      if (!moved.ok()) continue;
      std::vector<SurfacePoint> predicted;
      for (const auto& t : moved.value()) predicted.push_back(t.point);
      auto e = correspondence_error(m[j].mesh, predicted, m[j].corr);
      if (!e.ok()) continue;
      rows.push_back(Json{{"from", file_stem(meshes[i])}, {"to", file_stem(meshes[j])}, {"mean", e->mean},
                          {"under_0.05", e->under_005}, {"under_0.1", e->under_01}});
      mean += e->mean;
      u5 += e->under_005;
      u10 += e->under_01;
      ++pairs;
    }
  if (pairs == 0) return Json{{"error", "no ground truth pairs"}};
  return Json{{"folder", col_dir},      {"pairs", pairs},          {"mean_error", mean / pairs},
              {"under_0.05", u5 / pairs}, {"under_0.1", u10 / pairs}, {"per_pair", rows}};
}

int run_main_job(const RunArgs& a) {
  Stopwatch wall;
  const fs::path out_dir = fs::absolute(a.output).lexically_normal();
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) return print_error(Status(ErrorCode::IoError, out_dir.string() + ": cannot create folder: " + ec.message()));

  std::vector<std::string> inputs = a.meshes;
  const bool use_samples = inputs.empty();
  if (use_samples) {
    // Written to disk first so the job reads them like any user mesh, and so the user can
    // look at (and rerun on) exactly what was processed.
    const fs::path sample_dir = out_dir / "input";
    fs::create_directories(sample_dir, ec);
    if (ec) return print_error(Status(ErrorCode::IoError, sample_dir.string() + ": cannot create folder: " + ec.message()));
    auto collection = samples::make_sample_collection();
    if (!collection.ok()) return print_error(collection.status());
    if (Status s = samples::write_sample_collection(sample_dir.string(), collection.value()); !s.ok())
      return print_error(s);
    for (const samples::SampleMesh& m : collection.value()) inputs.push_back((sample_dir / (m.name + ".obj")).string());
    std::printf("Built-in samples written to %s\n", sample_dir.c_str());
  }

  Json report;
  report["version"] = kVersion;
  report["inputs"] = use_samples ? "built-in samples" : "command line";
  report["output_dir"] = out_dir.string();
  report["options"] = sphere_param_options_json(a.options);
  report["meshes"] = Json::array();

  const std::vector<std::string> columns = {"mesh",    "V",      "F",       "holes",  "efficiency", "Linf",
                                            "flips",   "winding", "PSNR129", "time s", "status"};
  Table table(columns);
  Json site;
  site["title"] = "SphereKit results";
  Json map_rows = Json::array();
  std::set<std::string> used;
  int worst = 0, failed = 0;
  for (const std::string& path : inputs) {
    MeshOutcome one = run_one(a, path, unique_stem(path, used), out_dir);
    if (cancel_requested()) return print_error(cancelled_status());
    if (one.exit_code != 0) ++failed;
    worst = worse_exit_code(worst, one.exit_code);
    report["meshes"].push_back(std::move(one.json));
    if (!one.model.is_null()) site["models"].push_back(std::move(one.model));
    map_rows.push_back(one.row);
    table.add_row(std::move(one.row));
  }
  site["tables"].push_back({{"label", "Sphere maps (as 'spherekit param'; efficiency = L2 stretch efficiency, PSNR of "
                                      "the 129 x 129 geometry image in dB)"},
                            {"columns", columns},
                            {"rows", map_rows}});

  // The consistent collection: the samples always (they share landmarks); user meshes when
  // there are at least two and each has its feature file beside it (NAME.lm.txt).
  bool collection = use_samples;
  if (!use_samples && inputs.size() >= 2) {
    collection = true;
    for (const std::string& path : inputs) {
      std::error_code ec;
      const fs::path lm = fs::path(path).parent_path() / (fs::path(path).stem().string() + ".lm.txt");
      if (!fs::is_regular_file(lm, ec)) collection = false;
    }
  }
  bool collection_done = false;
  if (collection && failed == 0) {
    std::printf("\nConsistent collection of the %s (as 'spherekit consistent'):\n",
                use_samples ? "samples" : "meshes");
    const std::string col_dir = (out_dir / "collection").string();
    const int code = run_consistent_job(inputs, col_dir, (out_dir / "collection_report.json").string(), a.quiet,
                                        a.options);
    worst = worse_exit_code(worst, code);
    if (code == 0 && use_samples) {
      // The samples have exact ground truth: measure the correspondence the collection induces.
      Json col = collection_correspondence_json(inputs, col_dir);
      report["collection"] = col;
      std::printf("correspondence vs. ground truth over %d ordered pairs: mean error %.4f, %.1f%% under 0.05, %.1f%% "
                  "under 0.1 (geodesic / sqrt(area))\n",
                  col["pairs"].get<int>(), col["mean_error"].get<double>(), 100 * col["under_0.05"].get<double>(),
                  100 * col["under_0.1"].get<double>());
      site["tables"].push_back({{"label", "Correspondence the consistent maps induce, against the samples' exact "
                                          "ground truth (geodesic error / sqrt(area))"},
                                {"columns", {"ordered pairs", "mean error", "under 0.05", "under 0.1"}},
                                {"rows", {{col["pairs"], col["mean_error"], col["under_0.05"], col["under_0.1"]}}}});
    }
    if (code == 0) {
      if (cancel_requested()) return print_error(cancelled_status());
      Json models_before = site["models"];
      const int stages = run_collection_stages(col_dir, out_dir.string(), a.quiet, site, report);
      worst = worse_exit_code(worst, stages);
      collection_done = stages == 0;
      if (stages != 0) site["models"] = models_before;
    }
  }
  site["description"] =
      std::string(use_samples ? "The built-in sample collection" : "The given meshes") +
      ", each mapped bijectively onto the sphere (Praun and Hoppe 2003)" +
      (collection_done ? " and all of them consistently onto one sphere (Asirvatham, Praun and Hoppe 2005). Every "
                         "asset below shares one layout: the same geometry-image texel, glTF vertex and cage vertex is "
                         "the same place on every member; that is what the morphs, the transfers and the PCA use."
                       : ". Each model is its 129 x 129 octahedral geometry image as Draco glTF levels of detail.") +
      " Files and numbers: report.json in this folder.";
  report["summary"] = Json{{"meshes", inputs.size()},
                           {"ok", static_cast<int>(inputs.size()) - failed},
                           {"failed", failed},
                           {"collection", collection_done},
                           {"wall_seconds", wall.seconds()},
                           {"cpu_seconds", cpu_seconds()},
                           {"peak_rss_mb", peak_rss_mb()}};

  std::vector<std::string> warnings;
  if (Status s = write_site_page(out_dir.string(), site, &warnings); !s.ok()) return print_error(s);
  for (const std::string& w : warnings) std::fprintf(stderr, "spherekit: warning: %s\n", w.c_str());
  report["page"] = (out_dir / "index.html").string();

  const std::string report_path = (out_dir / "report.json").string();
  if (Status s = write_json_atomic(report_path, report); !s.ok()) return print_error(s);

  std::printf("\n");
  table.print();
  std::printf("\n%d of %zu meshes mapped in %.1f s; sphere maps, geometry images, %sreport.json in:\n%s\n"
              "results page: %s\n",
              static_cast<int>(inputs.size()) - failed, inputs.size(), wall.seconds(),
              collection_done ? "the collection's assets and applications, " : "", out_dir.c_str(),
              (out_dir / "index.html").c_str());
  return worst;
}

}  // namespace

void register_run(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = add_command(
      app, "run", "The main job: check, map and measure meshes (default: built-in samples)",
      "The main job. For each MESH (default: the built-in sample collection, written first to\n"
      "OUT/input): check it, map it bijectively onto the sphere (as `param`), write\n"
      "OUT/<name>.sphere.obj, measure the map (as `eval`), build its 129 x 129 octahedral\n"
      "geometry image OUT/<name>.gim129.exr with the remesh PSNR (100000 samples per direction),\n"
      "PNG previews and 3 Draco glTF levels of detail (as `convert --size 129 --lods 3`).\n"
      "Then, for the samples, or for two or more meshes that each have a feature file beside\n"
      "them (NAME.lm.txt, as `consistent` reads them): map them consistently into\n"
      "OUT/collection (as `consistent`); convert every member into OUT/assets (as `convert\n"
      "--collection`: images, previews, LODs, Catmull-Clark cage 8 with 9 x 9 scalar\n"
      "displacement, the morph-target glTF); and run the applications into OUT/apps (colours\n"
      "and normals transferred from the first member, a morph of the first two, PCA with the\n"
      "compression experiment). For the samples it also measures the correspondence against\n"
      "their ground truth. Finally it writes OUT/report.json and OUT/index.html, a results page\n"
      "(3-D viewer of the glTF files with levels of detail and morph sliders, the images, plots\n"
      "and tables) that works opened from disk or served; its 3-D viewer needs three.js from npm\n"
      "(scripts/setup_viewer.sh; without it the page says so and shows the rest).\n"
      "A mesh that fails is reported and skipped; the exit code is then that of the worst failure.\n",
      "  spherekit run                              # built-in samples -> ./spherekit-out\n"
      "  spherekit run spot.obj bunny.obj -o maps   # your meshes -> ./maps\n"
      "  spherekit run ../shared/meshes/*.obj --effort 3");
  cmd->add_option("MESH", args->meshes, "input meshes (default: the built-in samples)");
  cmd->add_option("-o,--output", args->output, "output folder (created if missing)")->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "no progress output (the table is still printed)");
  add_sphere_param_options(*cmd, args->options);
  cmd->callback([args] { set_exit_code(run_main_job(*args)); });
}

}  // namespace spherekit::cli
