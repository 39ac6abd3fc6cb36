// run_main_job() (main_job.h): the main job composed in memory from the other jobs. What it
// shows on the results page is described as JSON for write_site_page() (site_page.h).
#include "spherekit/pipeline/main_job.h"
#include "spherekit/pipeline/landmarks.h"

#include <filesystem>
#include <set>

#include "sample_collection.h"
#include "spherekit/correspondence.h"
#include "spherekit/file_status.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/mesh_attributes.h"
#include "spherekit/formats/sphere_map_io.h"
#include "spherekit/formats/text_formats.h"
#include "spherekit/pipeline/json.h"
#include "spherekit/pipeline/mesh_input.h"
#include "spherekit/pipeline/process_stats.h"
#include "spherekit/pipeline/site_page.h"
#include "spherekit/version.h"
#include "spherekit/format_text.h"
#include "stopwatch.h"
#include "main_job_stages.h"

namespace fs = std::filesystem;

namespace spherekit::pipeline {

ProgressFn MainJobObserver::progress(const std::string&) { return {}; }
bool MainJobObserver::keep_going() { return true; }
void MainJobObserver::samples_written(const std::string&) {}
void MainJobObserver::failed(const Status&) {}
void MainJobObserver::heading(const std::string&) {}
void MainJobObserver::note(const std::string&) {}
void MainJobObserver::collection_made(const MakeCollectionResult&, const std::string&) {}
void MainJobObserver::correspondence(const Json&) {}
void MainJobObserver::assets_converted(const ConvertCollectionResult&) {}
void MainJobObserver::transferred(const TransferResult&, const TransferJob&) {}
void MainJobObserver::round_trip(const std::string&, const std::string&, double) {}
void MainJobObserver::morphed(const MorphResult&, const MorphJob&) {}
void MainJobObserver::pca_done(const PcaResult&, const PcaJob&) {}

namespace {


// glTF levels of detail per mesh from its image (129, 65, 33), for the page's 3-D view.
constexpr int kGeometryImageLods = 3;

std::string stem_of(const std::string& path) { return fs::path(path).stem().string(); }

// Output name for a mesh: its stem, made unique when two inputs share one (a/x.obj, b/x.ply).
std::string unique_stem(const std::string& path, std::set<std::string>& used) {
  const std::string stem = stem_of(path);
  std::string name = stem;
  for (int k = 2; !used.insert(name).second; ++k) name = stem + "_" + std::to_string(k);
  return name;
}

struct MeshOutcome {
  Json json;                     // the report entry
  std::vector<std::string> row;  // the summary-table row
  Json model;                    // the results page's model, when made
  Status error;
};

MeshOutcome run_one(const MainJob& a, const std::string& path, const std::string& name, const fs::path& out_dir,
                    MainJobObserver& observer) {
  MeshOutcome out;
  Stopwatch wall;
  out.json["file"] = path;
  out.json["name"] = name;
  auto fail = [&](const Status& status) {
    out.error = status;
    out.json["status"] = "failed";
    out.json["error"] = status.message();
    out.json["error_code"] = error_code_name(status.code());
    out.json["times"]["wall"] = wall.seconds();
    out.row = {name, "", "", "", "", "", "", "", "", format_text("%.2f", wall.seconds()),
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

  Stopwatch param_time;
  auto result = parameterize_sphere(m.mesh, a.options, observer.progress(name));
  const double param_seconds = param_time.seconds();
  if (!result.ok()) return fail(with_file(result.status(), path));
  const SphereParamResult& r = result.value();
  out.json["param"] = sphere_param_result_json(r);
  if (r.flipped_faces != 0)
    return fail(Status(ErrorCode::SolverFailed, format_text("%s: the map has %d flipped faces (not bijective); not written",
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

  // The octahedral geometry image of the map with its remesh PSNR, previews and levels of
  // detail: the pipeline `convert` runs (faces spanning holes of the mesh left out of the PSNR).
  const std::string gim_path = (out_dir / (name + ".gim" + std::to_string(kRunImageSize) + ".exr")).string();
  Stopwatch gim_time;
  ConvertOptions gio;
  gio.size = kRunImageSize;
  gio.psnr_samples = kRunPsnrSamples;
  gio.lods = kGeometryImageLods;
  gio.threads = a.options.threads;
  GeometryOutputs names;
  names.image = gim_path;
  names.prefix = output_prefix(gim_path);
  names.name = name;
  names.source_mesh = path;
  names.sphere_map = sphere_path;
  auto assets = convert_geometry(m.mesh, r.map.S, gio, names, /*collection_member=*/false, observer.progress(name));
  if (!assets.ok()) return fail(assets.status());
  const RemeshError& err = assets->error;
  const std::vector<std::string>& previews = assets->previews;
  const double gim_seconds = gim_time.seconds();
  Json lod_files = Json::array(), page_lods = Json::array();
  for (const std::string& f : assets->lod_paths.levels) {
    lod_files.push_back(f);
    page_lods.push_back(fs::path(f).filename().string());
  }
  out.json["geometry_image"] = Json{{"file", gim_path},
                                    {"size", kRunImageSize},
                                    {"psnr_db", number_or_null(err.psnr)},
                                    {"psnr_excludes_hole_faces", assets->image.texels_in_holes > 0},
                                    {"previews", previews},
                                    {"lods", lod_files},
                                    {"seconds", gim_seconds}};
  out.model = Json{{"name", name},
                   {"lods", page_lods},
                   {"images", Json::array({Json{{"label", "geometry image: normals"},
                                                {"png", fs::path(previews.at(0)).filename().string()}},
                                           Json{{"label", "geometry image: positions"},
                                                {"png", fs::path(previews.at(1)).filename().string()}}})}};

  out.json["status"] = "ok";
  out.json["times"] = Json{{"read", m.read_seconds},        {"check", m.check_seconds},
                           {"param", param_seconds},        {"write", write_seconds},
                           {"eval", eval_seconds},          {"geometry_image", gim_seconds},
                           {"wall", wall.seconds()}};
  out.row = {name,
             std::to_string(m.check.vertices),
             std::to_string(m.check.faces),
             std::to_string(m.check.boundary_loops),
             format_text("%.4f", e.efficiency),
             format_text("%.4g", e.linf),
             std::to_string(e.flipped),
             e.closed ? format_text("%.4f", e.winding) : std::string("-"),
             format_text("%.2f", err.psnr),
             format_text("%.2f", wall.seconds()),
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
    auto loaded = formats::read_mesh(path);
    if (!loaded.ok()) return Json{{"error", with_file(loaded.status(), path).message()}};
    auto map = formats::read_sphere_map((fs::path(col_dir) / (stem_of(path) + ".sphere.obj")).string(), loaded.value());
    if (!map.ok()) return Json{{"error", map.status().message()}};
    auto corr = formats::read_vertex_indices((fs::path(path).parent_path() / (stem_of(path) + ".corr.txt")).string());
    if (!corr.ok()) return Json{{"error", corr.status().message()}};
    m.push_back(Member{std::move(loaded).value(), map->S, std::move(corr).value()});
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
      rows.push_back(Json{{"from", stem_of(meshes[i])}, {"to", stem_of(meshes[j])}, {"mean", e->mean},
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

}  // namespace

Result<MainJobResult> run_main_job(const MainJob& a, MainJobObserver& observer) {
  Stopwatch wall;
  MainJobResult out;
  const fs::path out_dir = fs::absolute(a.output).lexically_normal();
  out.output_dir = out_dir.string();
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) return Status(ErrorCode::IoError, out_dir.string() + ": cannot create folder: " + ec.message());

  std::vector<std::string> inputs = a.meshes;
  const bool use_samples = inputs.empty();
  if (use_samples) {
    // Written to disk first so the job reads them like any user mesh, and so the user can
    // look at (and rerun on) exactly what was processed.
    const fs::path sample_dir = out_dir / "input";
    fs::create_directories(sample_dir, ec);
    if (ec) return Status(ErrorCode::IoError, sample_dir.string() + ": cannot create folder: " + ec.message());
    SPHEREKIT_ASSIGN_OR_RETURN(auto collection, samples::make_sample_collection());
    SPHEREKIT_RETURN_IF_ERROR(samples::write_sample_collection(sample_dir.string(), collection));
    for (const samples::SampleMesh& m : collection) inputs.push_back((sample_dir / (m.name + ".obj")).string());
    observer.samples_written(sample_dir.string());
  }

  Json& report = out.report;
  report["version"] = kVersion;
  report["inputs"] = use_samples ? "built-in samples" : "command line";
  report["output_dir"] = out_dir.string();
  report["options"] = sphere_param_options_json(a.options);
  report["meshes"] = Json::array();

  out.table_columns = {"mesh", "V", "F", "holes", "efficiency", "Linf", "flips", "winding", "PSNR129", "time s", "status"};
  Json site;
  site["title"] = "SphereKit results";
  Json map_rows = Json::array();
  std::set<std::string> used;
  for (const std::string& path : inputs) {
    MeshOutcome one = run_one(a, path, unique_stem(path, used), out_dir, observer);
    if (one.error.code() == ErrorCode::Cancelled) return one.error;
    if (!one.error.ok()) {
      ++out.failed;
      out.errors.push_back(one.error);
      observer.failed(one.error);
    }
    report["meshes"].push_back(std::move(one.json));
    if (!one.model.is_null()) site["models"].push_back(std::move(one.model));
    map_rows.push_back(one.row);
    out.table.push_back(std::move(one.row));
  }
  out.meshes = static_cast<int>(inputs.size());
  site["tables"].push_back({{"label", "Sphere maps (as 'spherekit param'; efficiency = L2 stretch efficiency, PSNR of "
                                      "the 129 x 129 geometry image in dB)"},
                            {"columns", out.table_columns},
                            {"rows", map_rows}});

  // The consistent collection: the samples always (they share landmarks); user meshes when
  // there are at least two and each has its feature file beside it (NAME.lm.txt).
  // Meshes without them get proposed landmarks (issue 25), written into OUT/landmarks/ (never
  // beside the user's meshes), and the collection is made with those.
  bool collection = use_samples;
  std::vector<std::string> feature_files;
  Json proposal_notes = Json::array();  // per member, for the page: confidence per name, mirror flag
  if (!use_samples && inputs.size() >= 2 && out.failed == 0) {
    collection = true;
    bool all = true;
    for (const std::string& path : inputs) {
      const fs::path lm = fs::path(path).parent_path() / (stem_of(path) + ".lm.txt");
      if (!fs::is_regular_file(lm, ec)) all = false;
    }
    if (!all) {
      LandmarksJob lj;
      lj.meshes = inputs;
      lj.output_dir = (out_dir / "landmarks").string();
      lj.options.threads = a.options.threads;
      auto lr = propose_landmark_files(lj, observer.progress("landmarks"));
      if (lr.status().code() == ErrorCode::Cancelled) return lr.status();
      if (!lr.ok()) {
        // The user gave no features: without a proposal the meshes are mapped alone, as before,
        // and the job has not failed.
        collection = false;
        observer.note("no corresponding landmarks could be proposed (" + lr.status().message() +
                      "): each mesh is mapped alone; give NAME.lm.txt files for a consistent collection");
      } else {
        feature_files = lr->files;
        for (std::size_t i = 0; i < lr->proposal.members.size(); ++i) {
          const LandmarkMemberMatch& mm = lr->proposal.members[i];
          Json confidence = Json::object();
          for (std::size_t k = 0; k < lr->proposal.landmarks[i].size(); ++k)
            confidence[lr->proposal.landmarks[i][k].name] = lr->proposal.confidence[i][k];
          proposal_notes.push_back(
              {{"confidence", confidence},
               {"note", mm.mirror_ambiguous ? "left/right undecided: check the left and right landmarks"
                        : mm.mirrored   ? "this member looks like a mirror image of the reference: check left and right"
                                        : ""}});
        }
        int flagged = 0;
        for (const auto& m : lr->proposal.members) flagged += m.mirror_ambiguous || m.mirrored;
        observer.note("the meshes came without feature files (NAME.lm.txt): proposed " +
                      std::to_string(lr->proposal.names.size()) + " corresponding landmarks (as 'spherekit landmarks') in " +
                      lj.output_dir + (flagged ? "; " + std::to_string(flagged) + " member(s) flagged left/right ambiguous or mirrored, see landmarks_report.json" : ""));
        if (Status s = formats::write_file_atomic((out_dir / "landmarks_report.json").string(), to_json(lj, *lr).dump(2) + "\n"); !s.ok())
          return s;
      }
    }
  }
  if (collection && out.failed == 0) {
    observer.heading(std::string("Consistent collection of the ") + (use_samples ? "samples" : "meshes") +
                     " (as 'spherekit consistent'):");
    const std::string col_dir = (out_dir / "collection").string();
    MakeCollectionJob cj;
    cj.meshes = inputs;
    cj.features = feature_files;
    cj.output = col_dir;
    // The collection stages' options, as `consistent` takes them (collection_sphere_options():
    // their anti-cruft weight, no coarse-layout precision), with the run's effort, seed,
    // threads, hole weight and alignment, and its anti-cruft and hole shape weights only where
    // the run was given other ones than param's defaults.
    SphereParamOptions so = collection_sphere_options();
    so.effort = a.options.effort;
    so.seed = a.options.seed;
    so.threads = a.options.threads;
    so.hole_weight = a.options.hole_weight;
    if (a.options.hole_shape_weight != SphereParamOptions{}.hole_shape_weight) so.hole_shape_weight = a.options.hole_shape_weight;
    so.align_rotation = a.options.align_rotation;
    if (a.options.regularizer_weight != SphereParamOptions{}.regularizer_weight) so.regularizer_weight = a.options.regularizer_weight;
    cj.options.constrained.sphere = so;
    cj.options.threads = a.options.threads;
    Stopwatch col_wall;
    auto made = make_collection(cj, observer.progress(""), [&] { return observer.keep_going(); });
    Status col_status = made.status();
    if (made.ok()) {
      // The report `consistent --report` writes.
      Json rep = formats::collection_manifest_json(made->manifest);
      rep["output"] = col_dir;
      rep["times"]["wall"] = col_wall.seconds();
      rep["cpu_seconds"] = cpu_seconds();
      rep["peak_rss_mb"] = peak_rss_mb();
      col_status = formats::write_file_atomic((out_dir / "collection_report.json").string(), rep.dump(2) + "\n");
    }
    if (col_status.code() == ErrorCode::Cancelled) return col_status;
    if (!col_status.ok() && !feature_files.empty()) {
      // Proposed landmarks (not the user's) did not give a collection: the per-mesh results
      // stand and the job has not failed; say so, with the reason.
      observer.note("the consistent collection with the proposed landmarks failed (" + col_status.message() +
                    "); the per-mesh results stand; check the landmarks in " + (out_dir / "landmarks").string());
    } else if (!col_status.ok()) {
      out.errors.push_back(col_status);
      observer.failed(col_status);
    } else {
      observer.collection_made(made.value(), col_dir);
      if (use_samples) {
        // The samples have exact ground truth: measure the correspondence the collection induces.
        Json col = collection_correspondence_json(inputs, col_dir);
        report["collection"] = col;
        observer.correspondence(col);
        site["tables"].push_back({{"label", "Correspondence the consistent maps induce, against the samples' exact "
                                            "ground truth (geodesic error / sqrt(area))"},
                                  {"columns", {"ordered pairs", "mean error", "under 0.05", "under 0.1"}},
                                  {"rows", {{col["pairs"], col["mean_error"], col["under_0.05"], col["under_0.1"]}}}});
      }
      Json models_before = site["models"];
      const Status stages = detail::run_collection_stages(col_dir, out_dir.string(), a.options.threads, observer, site, report);
      if (stages.code() == ErrorCode::Cancelled) return stages;
      out.collection_done = stages.ok();
      if (!stages.ok()) {
        out.errors.push_back(stages);
        observer.failed(stages);
        site["models"] = models_before;
      }
    }
  }
  site["description"] =
      std::string(use_samples ? "The built-in sample collection" : "The given meshes") +
      ", each mapped bijectively onto the sphere (Praun and Hoppe 2003)" +
      (out.collection_done ? " and all of them consistently onto one sphere (Asirvatham, Praun and Hoppe 2005). Every "
                             "asset below shares one layout: the same geometry-image texel, glTF vertex and cage vertex is "
                             "the same place on every member; that is what the morphs, the transfers and the PCA use."
                           : ". Each model is its 129 x 129 octahedral geometry image as Draco glTF levels of detail.") +
      " Files and numbers: report.json in this folder.";
  report["summary"] = Json{{"meshes", inputs.size()},
                           {"ok", static_cast<int>(inputs.size()) - out.failed},
                           {"failed", out.failed},
                           {"collection", out.collection_done},
                           {"wall_seconds", wall.seconds()},
                           {"cpu_seconds", cpu_seconds()},
                           {"peak_rss_mb", peak_rss_mb()}};

  // The page's landmark editor (issue 25): every mapped mesh with the landmarks this job used
  // (proposed into OUT/landmarks/, or the NAME.lm.txt beside it, or none yet), to check and fix.
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const Json& mesh = report["meshes"][i];
    if (mesh.value("status", "") != "ok") continue;
    std::string features = feature_files.empty() ? std::string() : feature_files[i];
    std::string source;
    if (!features.empty()) {
      source = "proposed by spherekit (as 'spherekit landmarks'): " + features +
               "; how sure each match is: landmarks_report.json";
    } else if (const fs::path beside = fs::path(inputs[i]).parent_path() / (stem_of(inputs[i]) + ".lm.txt");
               fs::is_regular_file(beside, ec)) {
      features = beside.string();
      source = "given: " + features;
    } else {
      source = "no landmark file yet (" + beside.string() + " does not exist)";
    }
    Json member = {{"name", mesh["name"]}, {"mesh", inputs[i]}, {"features", features}, {"source", source}};
    if (i < proposal_notes.size()) {
      member["confidence"] = proposal_notes[i]["confidence"];
      member["note"] = proposal_notes[i]["note"];
    }
    site["landmarks"]["members"].push_back(std::move(member));
  }

  SPHEREKIT_RETURN_IF_ERROR(write_site_page(out_dir.string(), site, &out.warnings));
  report["page"] = (out_dir / "index.html").string();
  SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic((out_dir / "report.json").string(), report.dump(2) + "\n"));
  out.wall_seconds = wall.seconds();
  return out;
}

}  // namespace spherekit::pipeline
