// shape_pca() (apps.h): PCA of a collection's consistent remeshes (mean shape, components,
// reconstruction errors) and the compression experiment against Draco.
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <map>

#include "spherekit/convert/consistent_remesh.h"
#include "spherekit/convert/gltf_morph.h"
#include "spherekit/convert/line_plot.h"
#include "spherekit/convert/png_image.h"
#include "spherekit/convert/shape_compression.h"
#include "spherekit/convert/shape_pca.h"
#include "spherekit/formats/collection.h"
#include "spherekit/formats/mesh_attributes.h"
#include "spherekit/geometry_image.h"
#include "spherekit/pipeline/apps.h"
#include "spherekit/format_text.h"
#include "stopwatch.h"

namespace spherekit::pipeline {
namespace {

using formats::LoadedMember;
using formats::OutputFiles;


std::string csv_number(double x) { return std::isfinite(x) ? format_text("%.9g", x) : std::string("inf"); }

Result<std::string> mesh_obj_text(const TriMesh& mesh) { return formats::format_mesh_with_attributes("m.obj", mesh, {}); }

Result<std::string> png_of(const convert::LinePlot& plot) {
  SPHEREKIT_ASSIGN_OR_RETURN(convert::Image8 image, convert::render_line_plot(plot));
  return convert::encode_png(image);
}

// A colour per member (tab10-like palette), cycling.
std::array<std::uint8_t, 3> palette(std::size_t i) {
  static const std::array<std::uint8_t, 3> k[] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                                                  {148, 103, 189}, {140, 86, 75},  {227, 119, 194}, {127, 127, 127}};
  return k[i % 8];
}

}  // namespace

Result<PcaResult> shape_pca(const PcaJob& a, const ProgressFn& progress,
                            const formats::KeepGoingFn& keep_going) {
  if (!is_geometry_image_size(a.size))
    return Status(ErrorCode::InvalidArgument, "--size " + std::to_string(a.size) + " is not 2^k+1 (33, 65, 129, ...)");
  if (Status s = formats::require_staged_folder_target(a.output, kPcaReport); !s.ok()) return s;
  Stopwatch clock;
  auto col = formats::read_collection(a.collection);
  if (!col.ok()) return col.status();
  auto members = formats::load_collection_members(col.value());
  if (!members.ok()) return members.status();
  if (members->size() < 2)
    return Status(ErrorCode::InvalidInput, a.collection + ": PCA needs at least 2 members, the collection has " +
                                                           std::to_string(members->size()));
  std::vector<TriMesh> meshes;
  std::vector<RowMat3d> maps;
  for (const LoadedMember& m : members.value()) {
    meshes.push_back(m.mesh);
    maps.push_back(m.map.S);
  }

  std::vector<TriMesh> shapes;
  std::vector<convert::CompressionPoint> compression;
  convert::ShapePca pca;
  convert::PcaErrorTable table;
  {
    auto r = convert::consistent_remeshes(meshes, maps, a.size, GeometryImageOptions{.threads = a.threads}, progress);
    if (!r.ok()) return r.status();
    for (auto& rm : r.value()) shapes.push_back(std::move(rm.mesh));
    auto p = convert::compute_shape_pca(shapes);
    if (!p.ok()) return p.status();
    pca = std::move(p).value();
    auto t = convert::pca_error_table(pca, shapes);
    if (!t.ok()) return t.status();
    table = std::move(t).value();
    if (a.compression) {
      auto c = convert::compression_experiment(pca, shapes, {}, progress);
      if (!c.ok()) return c.status();
      compression = std::move(c).value();
    }
  }
  const auto r = static_cast<int>(pca.components.size());
  const std::size_t n = shapes.size();

  OutputFiles files;
  auto add_mesh = [&](const std::string& name, const TriMesh& m) -> Status {
    SPHEREKIT_ASSIGN_OR_RETURN(std::string text, mesh_obj_text(m));
    files.add(name, std::move(text));
    return Status();
  };
  if (Status s = add_mesh("mean.obj", TriMesh{pca.mean, pca.F}); !s.ok()) return s;
  // Components shown as the mean moved by +-2 standard deviations (Fig. 1 adds them to the
  // average); the glTF holds them at one standard deviation as morph targets.
  std::vector<TriMesh> gltf_members{TriMesh{pca.mean, pca.F}};
  std::vector<std::string> names{"mean"};
  for (int j = 0; j < r; ++j) {
    const RowMat3d d = pca.sigma[static_cast<std::size_t>(j)] * pca.components[static_cast<std::size_t>(j)];
    if (Status s = add_mesh(format_text("pc%d_plus.obj", j + 1), TriMesh{pca.mean + 2 * d, pca.F}); !s.ok()) return s;
    if (Status s = add_mesh(format_text("pc%d_minus.obj", j + 1), TriMesh{pca.mean - 2 * d, pca.F}); !s.ok()) return s;
    gltf_members.push_back(TriMesh{pca.mean + d, pca.F});
    names.push_back(format_text("pc%d", j + 1));
  }
  convert::GltfMorphOptions g;
  g.name = "pca";
  g.names = names;
  g.provenance.sphere_map = a.collection;
  auto glb = convert::build_gltf_morph_targets(gltf_members, g);
  if (!glb.ok()) return glb.status();
  files.add("pca.glb", glb->glb);

  // The error table: CSV (one row per k) and JSON.
  std::string csv = "components";
  for (const LoadedMember& m : members.value()) csv += ",rms_" + m.name;
  for (const LoadedMember& m : members.value()) csv += ",psnr_" + m.name;
  csv += ",mean_rms,max_rms,mean_psnr\n";
  Json rows = Json::array();
  for (int k = 0; k <= r; ++k) {
    csv += std::to_string(k);
    Json rms = Json::array(), psnr = Json::array();
    for (std::size_t i = 0; i < n; ++i) {
      csv += "," + csv_number(table.rms(k, static_cast<Eigen::Index>(i)));
      rms.push_back(table.rms(k, static_cast<Eigen::Index>(i)));
    }
    for (std::size_t i = 0; i < n; ++i) {
      csv += "," + csv_number(table.psnr(k, static_cast<Eigen::Index>(i)));
      psnr.push_back(number_or_null(table.psnr(k, static_cast<Eigen::Index>(i))));
    }
    const auto kk = static_cast<std::size_t>(k);
    csv += "," + csv_number(table.mean_rms[kk]) + "," + csv_number(table.max_rms[kk]) + "," +
           csv_number(table.mean_psnr[kk]) + "\n";
    rows.push_back({{"components", k}, {"rms", rms}, {"psnr_db", psnr}, {"mean_rms", table.mean_rms[kk]},
                    {"max_rms", table.max_rms[kk]}, {"mean_psnr_db", number_or_null(table.mean_psnr[kk])}});
  }
  files.add("pca_errors.csv", csv);

  // Plot: RMS error in % of each member's bounding-box diagonal versus components.
  convert::LinePlot plot;
  plot.title = "PCA reconstruction error";
  plot.x_label = "number of components";
  plot.y_label = "RMS vertex error (% of bounding-box diagonal)";
  plot.y_from_zero = true;
  convert::PlotSeries mean_series{"mean", {}, {}, {0, 0, 0}, 3, true};
  for (std::size_t i = 0; i < n; ++i) {
    convert::PlotSeries s{members.value()[i].name, {}, {}, palette(i), 1, true};
    for (int k = 0; k <= r; ++k) {
      s.x.push_back(k);
      s.y.push_back(100 * table.rms(k, static_cast<Eigen::Index>(i)) / table.peak[i]);
    }
    plot.series.push_back(std::move(s));
  }
  for (int k = 0; k <= r; ++k) {
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) sum += 100 * table.rms(k, static_cast<Eigen::Index>(i)) / table.peak[i];
    mean_series.x.push_back(k);
    mean_series.y.push_back(sum / static_cast<double>(n));
  }
  plot.series.push_back(std::move(mean_series));
  auto png = png_of(plot);
  if (!png.ok()) return png.status();
  files.add("pca_errors.png", std::move(png).value());

  Json comp = Json::array();
  if (!compression.empty()) {
    std::string ccsv = "method,components,bits,bytes_per_shape,deflated_bytes_per_shape,mean_rms,max_rms,mean_psnr\n";
    convert::LinePlot cp;
    cp.title = "Bytes per shape versus error";
    cp.x_label = "bytes per shape (log scale; PCA after deflate)";
    cp.y_label = "mean PSNR (dB, peak = bounding-box diagonal)";
    cp.log_x = true;
    std::map<std::string, convert::PlotSeries> series;
    std::vector<std::string> order;
    for (const convert::CompressionPoint& p : compression) {
      ccsv += p.method + "," + std::to_string(p.components) + "," + std::to_string(p.bits) + "," +
              csv_number(p.bytes_per_shape) + "," + csv_number(p.deflated_bytes_per_shape) + "," + csv_number(p.mean_rms) +
              "," + csv_number(p.max_rms) + "," + csv_number(p.mean_psnr) + "\n";
      comp.push_back({{"method", p.method}, {"components", p.components}, {"bits", p.bits},
                      {"bytes_per_shape", p.bytes_per_shape}, {"deflated_bytes_per_shape", p.deflated_bytes_per_shape},
                      {"mean_rms", p.mean_rms}, {"max_rms", p.max_rms}, {"mean_psnr_db", number_or_null(p.mean_psnr)}});
      const std::string key = p.method == "draco" ? "Draco, each shape alone"
                                                  : (p.bits == 0 ? std::string("PCA float32") : format_text("PCA %d-bit", p.bits));
      if (!series.count(key)) {
        order.push_back(key);
        series[key] = convert::PlotSeries{key, {}, {}, p.method == "draco" ? std::array<std::uint8_t, 3>{214, 39, 40}
                                                                            : palette(order.size() - 1), 2, true};
      }
      series[key].x.push_back(p.deflated_bytes_per_shape);
      series[key].y.push_back(p.mean_psnr);
    }
    for (const std::string& k : order) cp.series.push_back(series[k]);
    files.add("compression.csv", ccsv);
    auto cpng = png_of(cp);
    if (!cpng.ok()) return cpng.status();
    files.add("compression.png", std::move(cpng).value());
  }

  Json rep;
  rep["command"] = "pca";
  rep["collection"] = a.collection;
  rep["size"] = a.size;
  rep["members"] = Json::array();
  for (std::size_t i = 0; i < n; ++i) {
    // Row i of a column-major matrix is strided: copied element by element.
    std::vector<double> c;
    for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(r); ++j) c.push_back(pca.coefficients(static_cast<Eigen::Index>(i), j));
    rep["members"].push_back({{"name", members.value()[i].name}, {"peak", table.peak[i]}, {"coefficients", c}});
  }
  rep["vertices"] = pca.mean.rows();
  rep["faces"] = pca.F.rows();
  rep["components"] = r;
  rep["singular_values"] = pca.singular_values;
  rep["sigma"] = pca.sigma;
  rep["variance_fraction"] = pca.variance_fraction;
  rep["errors"] = rows;
  rep["compression"] = comp;
  Json out_files = Json::array();
  for (const auto& f : files.files()) out_files.push_back(f.first);
  rep["files"] = out_files;
  rep["seconds"] = clock.seconds();
  files.add(kPcaReport, rep.dump(2) + "\n");
  SPHEREKIT_RETURN_IF_ERROR(formats::write_output_folder(a.output, kPcaReport, files, keep_going));
  PcaResult result;
  result.report = std::move(rep);
  return result;
}

}  // namespace spherekit::pipeline
