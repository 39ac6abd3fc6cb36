// The collection half of the main job (paper §5): once the members are mapped consistently,
// convert them all (geometry images, previews, glTF levels of detail, Catmull-Clark cages with
// displacement, the morph-target glTF) and run the applications on them (attribute transfer,
// a morph sequence, PCA with the compression experiment), each exactly as its own command
// does it, then describe the results for the page (site_page.h).
#include <filesystem>

#include "main_job_stages.h"
#include "spherekit/formats/collection.h"
#include "spherekit/formats/mesh_attributes.h"

namespace fs = std::filesystem;

namespace spherekit::pipeline::detail {
namespace {

// What the main job converts each member into: images large enough to look at, three levels
// of detail (129, 65, 33), a cage of 8 x 8 quads per cube face with 9 x 9 scalar displacement
// samples per quad, and PSNRs from kRunPsnrSamples samples per direction (main_job.h).
constexpr int kLods = 3;
constexpr int kCage = 8;
constexpr int kCageTile = 9;

// One transfer as `transfer` does it (default options). `tell`: the observer hears of it
// (the colour round trip's way back is only measured).
Status transfer(MainJobObserver& observer, const std::string& col, const std::string& from, const std::string& to,
                TransferWhat what, const std::string& output, const std::string& attributes, int threads,
                bool tell = true) {
  TransferJob job;
  job.collection = col;
  job.from = from;
  job.to = to;
  job.what = what;
  job.output = output;
  job.attributes = attributes;
  job.threads = threads;
  SPHEREKIT_ASSIGN_OR_RETURN(TransferResult r, transfer_attributes(job));
  if (tell) observer.transferred(r, job);
  return Status();
}

// Mean distance between two colour tables of the same size (rows are RGB in [0, 1]).
double mean_color_distance(const RowMat3d& a, const RowMat3d& b) {
  if (a.rows() != b.rows() || a.rows() == 0) return -1;
  return (a - b).rowwise().norm().mean();
}

}  // namespace

Status run_collection_stages(const std::string& col_dir, const std::string& out_dir, int threads,
                             MainJobObserver& observer, Json& site, Json& report) {
  auto info = formats::read_collection(col_dir);
  if (!info.ok()) return info.status();
  std::vector<std::string> names;
  for (const formats::CollectionMember& m : info->manifest.members) names.push_back(m.name);
  if (names.size() < 2) return Status();  // nothing to relate: the per-mesh results are all there is

  // 1. Convert every member (as `convert --collection`).
  observer.heading("Converting the collection (as 'spherekit convert --collection'):");
  ConvertCollectionJob cj;
  cj.collection = col_dir;
  cj.output = (fs::path(out_dir) / "assets").string();
  cj.options.size = kRunImageSize;
  cj.options.lods = kLods;
  cj.options.cage = kCage;
  cj.options.cage_tile = kCageTile;
  cj.options.psnr_samples = kRunPsnrSamples;
  cj.options.threads = threads;
  auto converted = convert_collection(cj, observer.progress(""), [&] { return observer.keep_going(); });
  if (!converted.ok()) return converted.status();
  observer.assets_converted(converted.value());
  const Json& conv = converted->report;
  report["assets"] = conv;

  Json models = Json::array();
  Json assets_table = Json::array();
  for (const Json& m : conv["members"]) {
    const std::string name = m["name"].get<std::string>();
    Json lods = Json::array();
    for (const Json& l : m["lods"]) lods.push_back("assets/" + l["file"].get<std::string>());
    Json images = Json::array();
    images.push_back({{"label", "geometry image: normals"}, {"png", "assets/" + name + "_normals.png"}});
    images.push_back({{"label", "geometry image: positions"}, {"png", "assets/" + name + "_positions.png"}});
    models.push_back({{"name", name}, {"lods", lods}, {"images", images}});
    const Json& c = m["cage"];
    assets_table.push_back({name, m["V"], m["image"].value("psnr_db", Json(nullptr)), c.value("psnr_db_limit", Json(nullptr)),
                            c.value("psnr_db", Json(nullptr)), m["lods"][0]["bytes"], m["seconds"]});
  }
  site["models"] = models;
  site["tables"].push_back({{"label", "Converted assets (PSNR in dB: peak = bounding-box diagonal, symmetric RMS "
                                      "surface distance)"},
                            {"columns", {"member", "vertices", "geometry image 129", "cage 8 limit",
                                         "cage 8 + displacement 9x9", "glTF LOD0 bytes", "seconds"}},
                            {"rows", assets_table}});
  // The members as targets of one base: one slider runs from the first member through the others.
  site["morph"].push_back({{"glb", "assets/collection_morph.glb"},
                           {"label", "all members as morph targets of one glTF (same vertex order)"},
                           {"mode", "sequence"}});

  // 2. Attribute transfer (as `transfer`): colours painted on the first member (its position
  // in the bounding box) carried to every other member, and back from the second as a check;
  // the first member's normals carried to the second as a normal map.
  observer.heading("Attribute transfer (as 'spherekit transfer'):");
  const fs::path tdir = fs::path(out_dir) / "apps" / "transfer";
  std::error_code ec;
  fs::create_directories(tdir, ec);
  if (ec) return Status(ErrorCode::IoError, tdir.string() + ": cannot create folder: " + ec.message());
  auto first = formats::load_collection_member(info.value(), names[0]);
  if (!first.ok()) return first.status();
  const TriMesh& first_mesh = first->mesh;
  formats::MeshAttributes painted;
  {
    const Eigen::RowVector3d lo = first_mesh.V.colwise().minCoeff(), hi = first_mesh.V.colwise().maxCoeff();
    const Eigen::RowVector3d extent = (hi - lo).cwiseMax(1e-300);
    painted.colors = (first_mesh.V.rowwise() - lo).array().rowwise() / extent.array();
  }
  const std::string painted_path = (tdir / (names[0] + "_painted.ply")).string();
  if (Status s = formats::write_mesh_with_attributes(painted_path, first_mesh, painted); !s.ok())
    return s;
  Json transfer_rows = Json::array();
  for (std::size_t k = 1; k < names.size(); ++k) {
    const std::string to = (tdir / (names[k] + "_colors.ply")).string();
    SPHEREKIT_RETURN_IF_ERROR(transfer(observer, col_dir, names[0], names[k], TransferWhat::Colors, to, painted_path, threads));
    transfer_rows.push_back({names[0], names[k], "colors", "apps/transfer/" + names[k] + "_colors.ply", nullptr});
  }
  {  // the round trip: first -> second -> first, compared with what was painted
    const std::string back = (tdir / (names[0] + "_colors_back.ply")).string();
    SPHEREKIT_RETURN_IF_ERROR(transfer(observer, col_dir, names[1], names[0], TransferWhat::Colors, back,
                                       (tdir / (names[1] + "_colors.ply")).string(), threads, /*tell=*/false));
    auto read_back = formats::read_mesh_with_attributes(back);
    if (!read_back.ok()) return read_back.status();
    const double err = mean_color_distance(read_back->attributes.colors, painted.colors);
    transfer_rows.push_back({names[1], names[0], "colors (round trip)", "apps/transfer/" + names[0] + "_colors_back.ply",
                             err});
    report["transfer"] = {{"painted", painted_path}, {"round_trip_mean_color_error", err}};
    observer.round_trip(names[0], names[1], err);
  }
  const std::string normals_out = (tdir / (names[1] + "_normals.obj")).string();
  SPHEREKIT_RETURN_IF_ERROR(transfer(observer, col_dir, names[0], names[1], TransferWhat::Normals, normals_out, "", threads));
  transfer_rows.push_back({names[0], names[1], "normals (normal map)", "apps/transfer/" + names[1] + "_normals.obj",
                           nullptr});
  site["tables"].push_back({{"label", "Attribute transfer through the sphere (round trip: mean RGB distance)"},
                            {"columns", {"from", "to", "what", "file", "round-trip error"}},
                            {"rows", transfer_rows}});
  site["plots"].push_back({{"label", "normal map of " + names[0] + " on " + names[1] + "'s consistent remesh"},
                           {"png", "apps/transfer/" + names[1] + "_normals_normals.png"}});

  // 3. A morph sequence between the first two members (as `morph`).
  observer.heading("Morph (as 'spherekit morph'):");
  {
    MorphJob job;
    job.collection = col_dir;
    job.a = names[0];
    job.b = names[1];
    job.output = (fs::path(out_dir) / "apps" / "morph").string();
    job.threads = threads;
    SPHEREKIT_ASSIGN_OR_RETURN(MorphResult r, morph_members(job, observer.progress("morph"), [&] { return observer.keep_going(); }));
    observer.morphed(r, job);
  }
  site["morph"].push_back({{"glb", "apps/morph/morph.glb"},
                           {"label", "morph " + names[0] + " to " + names[1]},
                           {"mode", "sequence"}});

  // 4. PCA and the compression experiment (as `pca`).
  observer.heading("Shape statistics (as 'spherekit pca'):");
  const std::string pca_dir = (fs::path(out_dir) / "apps" / "pca").string();
  PcaJob pca_job;
  pca_job.collection = col_dir;
  pca_job.output = pca_dir;
  pca_job.threads = threads;
  auto pca = shape_pca(pca_job, observer.progress("pca"), [&] { return observer.keep_going(); });
  if (!pca.ok()) return pca.status();
  observer.pca_done(pca.value(), pca_job);
  report["pca"] = {{"folder", pca_dir}, {"components", pca->report["components"]}, {"errors", pca->report["errors"]}};
  site["morph"].push_back({{"glb", "apps/pca/pca.glb"},
                           {"label", "principal components around the mean shape (one slider each)"},
                           {"mode", "weights"}});
  site["plots"].push_back({{"label", "PCA: reconstruction error versus number of components"},
                           {"png", "apps/pca/pca_errors.png"}});
  if (fs::exists(fs::path(pca_dir) / "compression.png"))
    site["plots"].push_back({{"label", "Compression: bytes per shape versus error, PCA model against Draco"},
                             {"png", "apps/pca/compression.png"}});
  Json pca_rows = Json::array();
  for (const Json& e : pca->report["errors"])
    pca_rows.push_back({e["components"], e["mean_rms"], e["max_rms"], e["mean_psnr_db"]});
  site["tables"].push_back({{"label", "PCA reconstruction error (RMS vertex distance; PSNR in dB)"},
                            {"columns", {"components", "mean RMS", "max RMS", "mean PSNR"}},
                            {"rows", pca_rows}});
  return Status();
}

}  // namespace spherekit::pipeline::detail
