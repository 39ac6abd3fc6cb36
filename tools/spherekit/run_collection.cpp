// The collection half of `spherekit run` (paper §5): once the members are mapped consistently,
// convert them all (geometry images, previews, glTF levels of detail, Catmull-Clark cages with
// displacement, the morph-target glTF) and run the applications on them (attribute transfer,
// a morph sequence, PCA with the compression experiment), each exactly as its own command
// does it, then describe the results for the page (site_page.h).
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_common.h"
#include "collection.h"
#include "commands.h"
#include "convert_common.h"
#include "member_io.h"
#include "run_job.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/mesh_attributes.h"
#include "spherekit/formats/mesh_io.h"

namespace fs = std::filesystem;

namespace spherekit::cli {
namespace {

// What the main job converts each member into: images large enough to look at, three levels
// of detail (129, 65, 33), a cage of 8 x 8 quads per cube face with 9 x 9 scalar displacement
// samples per quad, and PSNRs from kRunPsnrSamples samples per direction (run_job.h).
constexpr int kLods = 3;
constexpr int kCage = 8;
constexpr int kCageTile = 9;

Result<Json> read_json_file(const std::string& path) {
  SPHEREKIT_ASSIGN_OR_RETURN(std::string text, formats::read_file(path));
  Json j = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return Status(ErrorCode::ParseError, path + ": not valid JSON");
  return j;
}

void heading(bool quiet, const char* text) {
  if (!quiet) std::printf("\n%s\n", text);
  std::fflush(stdout);
}

// Mean distance between two colour tables of the same size (rows are RGB in [0, 1]).
double mean_color_distance(const RowMat3d& a, const RowMat3d& b) {
  if (a.rows() != b.rows() || a.rows() == 0) return -1;
  return (a - b).rowwise().norm().mean();
}

}  // namespace

int run_collection_stages(const std::string& col_dir, const std::string& out_dir, bool quiet, Json& site,
                          Json& report) {
  auto info = read_collection(col_dir);
  if (!info.ok()) return print_error(info.status());
  std::vector<std::string> names;
  for (const Json& m : info->manifest["meshes"]) names.push_back(m["name"].get<std::string>());
  if (names.size() < 2) return 0;  // nothing to relate: the per-mesh results are all there is

  // 1. Convert every member (as `convert --collection`).
  heading(quiet, "Converting the collection (as 'spherekit convert --collection'):");
  ConvertArgs ca;
  ca.collection = col_dir;
  ca.output = (fs::path(out_dir) / "assets").string();
  ca.size = kRunImageSize;
  ca.lods = kLods;
  ca.cage = kCage;
  ca.cage_tile = kCageTile;
  ca.psnr_samples = kRunPsnrSamples;
  ca.quiet = quiet;
  if (int code = run_convert_collection(ca); code != 0) return code;
  auto conv = read_json_file((fs::path(ca.output) / "convert_report.json").string());
  if (!conv.ok()) return print_error(conv.status());
  report["assets"] = conv.value();

  Json models = Json::array();
  Json assets_table = Json::array();
  for (const Json& m : conv.value()["members"]) {
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
  heading(quiet, "Attribute transfer (as 'spherekit transfer'):");
  const fs::path tdir = fs::path(out_dir) / "apps" / "transfer";
  std::error_code ec;
  fs::create_directories(tdir, ec);
  if (ec) return print_error(Status(ErrorCode::IoError, tdir.string() + ": cannot create folder: " + ec.message()));
  auto first = load_member(info.value(), names[0]);
  if (!first.ok()) return print_error(first.status());
  const TriMesh& first_mesh = first->mesh;
  formats::MeshAttributes painted;
  {
    const Eigen::RowVector3d lo = first_mesh.V.colwise().minCoeff(), hi = first_mesh.V.colwise().maxCoeff();
    const Eigen::RowVector3d extent = (hi - lo).cwiseMax(1e-300);
    painted.colors = (first_mesh.V.rowwise() - lo).array().rowwise() / extent.array();
  }
  const std::string painted_path = (tdir / (names[0] + "_painted.ply")).string();
  if (Status s = formats::write_mesh_with_attributes(painted_path, first_mesh, painted); !s.ok())
    return print_error(s);
  Json transfer_rows = Json::array();
  for (std::size_t k = 1; k < names.size(); ++k) {
    const std::string to = (tdir / (names[k] + "_colors.ply")).string();
    if (int code = run_transfer_job(col_dir, names[0], names[k], "colors", to, painted_path, "", quiet); code != 0)
      return code;
    transfer_rows.push_back({names[0], names[k], "colors", "apps/transfer/" + names[k] + "_colors.ply", nullptr});
  }
  {  // the round trip: first -> second -> first, compared with what was painted
    const std::string back = (tdir / (names[0] + "_colors_back.ply")).string();
    if (int code = run_transfer_job(col_dir, names[1], names[0], "colors", back,
                                    (tdir / (names[1] + "_colors.ply")).string(), "", true);
        code != 0)
      return code;
    auto read_back = formats::read_mesh_with_attributes(back);
    if (!read_back.ok()) return print_error(read_back.status());
    const double err = mean_color_distance(read_back->attributes.colors, painted.colors);
    transfer_rows.push_back({names[1], names[0], "colors (round trip)", "apps/transfer/" + names[0] + "_colors_back.ply",
                             err});
    report["transfer"] = {{"painted", painted_path}, {"round_trip_mean_color_error", err}};
    if (!quiet) std::printf("colour round trip %s -> %s -> %s: mean error %.4f (RGB in [0, 1])\n", names[0].c_str(),
                            names[1].c_str(), names[0].c_str(), err);
  }
  const std::string normals_out = (tdir / (names[1] + "_normals.obj")).string();
  if (int code = run_transfer_job(col_dir, names[0], names[1], "normals", normals_out, "", "", quiet); code != 0)
    return code;
  transfer_rows.push_back({names[0], names[1], "normals (normal map)", "apps/transfer/" + names[1] + "_normals.obj",
                           nullptr});
  site["tables"].push_back({{"label", "Attribute transfer through the sphere (round trip: mean RGB distance)"},
                            {"columns", {"from", "to", "what", "file", "round-trip error"}},
                            {"rows", transfer_rows}});
  site["plots"].push_back({{"label", "normal map of " + names[0] + " on " + names[1] + "'s consistent remesh"},
                           {"png", "apps/transfer/" + names[1] + "_normals_normals.png"}});

  // 3. A morph sequence between the first two members (as `morph`).
  heading(quiet, "Morph (as 'spherekit morph'):");
  if (int code = run_morph_job(col_dir, names[0], names[1], (fs::path(out_dir) / "apps" / "morph").string(), quiet);
      code != 0)
    return code;
  site["morph"].push_back({{"glb", "apps/morph/morph.glb"},
                           {"label", "morph " + names[0] + " to " + names[1]},
                           {"mode", "sequence"}});

  // 4. PCA and the compression experiment (as `pca`).
  heading(quiet, "Shape statistics (as 'spherekit pca'):");
  const std::string pca_dir = (fs::path(out_dir) / "apps" / "pca").string();
  if (int code = run_pca_job(col_dir, pca_dir, quiet); code != 0) return code;
  auto pca = read_json_file((fs::path(pca_dir) / "pca.json").string());
  if (!pca.ok()) return print_error(pca.status());
  report["pca"] = {{"folder", pca_dir}, {"components", pca.value()["components"]}, {"errors", pca.value()["errors"]}};
  site["morph"].push_back({{"glb", "apps/pca/pca.glb"},
                           {"label", "principal components around the mean shape (one slider each)"},
                           {"mode", "weights"}});
  site["plots"].push_back({{"label", "PCA: reconstruction error versus number of components"},
                           {"png", "apps/pca/pca_errors.png"}});
  if (fs::exists(fs::path(pca_dir) / "compression.png"))
    site["plots"].push_back({{"label", "Compression: bytes per shape versus error, PCA model against Draco"},
                             {"png", "apps/pca/compression.png"}});
  Json pca_rows = Json::array();
  for (const Json& e : pca.value()["errors"])
    pca_rows.push_back({e["components"], e["mean_rms"], e["max_rms"], e["mean_psnr_db"]});
  site["tables"].push_back({{"label", "PCA reconstruction error (RMS vertex distance; PSNR in dB)"},
                            {"columns", {"components", "mean RMS", "max RMS", "mean PSNR"}},
                            {"rows", pca_rows}});
  return 0;
}

}  // namespace spherekit::cli
