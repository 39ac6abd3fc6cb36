// `spherekit pca`: the average shape and principal components of a collection (paper Fig. 1),
// the reconstruction error versus the number of components, and the compression experiment
// (PCA model versus Draco on each shape). The algorithms are convert/shape_pca.h and
// convert/shape_compression.h; this file reads, calls, tabulates, plots and writes.
#include <CLI/CLI.hpp>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "convert_common.h"  // number_or_null
#include "member_io.h"
#include "spherekit/convert/consistent_remesh.h"
#include "spherekit/convert/gltf_morph.h"
#include "spherekit/convert/line_plot.h"
#include "spherekit/convert/png_image.h"
#include "spherekit/convert/shape_compression.h"
#include "spherekit/convert/shape_pca.h"
#include "spherekit/formats/mesh_attributes.h"
#include "spherekit/geometry_image.h"

namespace spherekit::cli {
namespace {

constexpr const char* kPcaReport = "pca.json";

struct PcaArgs {
  std::string dir, output;
  int size = 65;
  bool no_compression = false;
  bool quiet = false;
};

std::string csv_number(double x) { return std::isfinite(x) ? strprintf("%.9g", x) : std::string("inf"); }

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

int run_pca(const PcaArgs& a) {
  if (!is_geometry_image_size(a.size))
    return print_error(Status(ErrorCode::InvalidArgument, "--size " + std::to_string(a.size) + " is not 2^k+1 (33, 65, 129, ...)"));
  if (Status s = require_output_folder(a.output, kPcaReport); !s.ok()) return print_error(s);
  Stopwatch clock;
  auto col = read_collection(a.dir);
  if (!col.ok()) return print_error(col.status());
  auto members = load_all_members(col.value());
  if (!members.ok()) return print_error(members.status());
  if (members->size() < 2)
    return print_error(Status(ErrorCode::InvalidInput, a.dir + ": PCA needs at least 2 members, the collection has " +
                                                           std::to_string(members->size())));
  std::vector<TriMesh> meshes;
  std::vector<RowMat3d> maps;
  for (const Member& m : members.value()) {
    meshes.push_back(m.mesh);
    maps.push_back(m.map.S);
  }

  ProgressRenderer progress(a.quiet, "pca");
  std::vector<TriMesh> shapes;
  std::vector<convert::CompressionPoint> compression;
  convert::ShapePca pca;
  convert::PcaErrorTable table;
  {
    ComputeScope graceful_cancel;
    auto r = convert::consistent_remeshes(meshes, maps, a.size, {}, progress.callback());
    if (!r.ok()) return print_error(cancel_requested() ? cancelled_status() : r.status());
    for (auto& rm : r.value()) shapes.push_back(std::move(rm.mesh));
    auto p = convert::compute_shape_pca(shapes);
    if (!p.ok()) return print_error(p.status());
    pca = std::move(p).value();
    auto t = convert::pca_error_table(pca, shapes);
    if (!t.ok()) return print_error(t.status());
    table = std::move(t).value();
    if (!a.no_compression) {
      auto c = convert::compression_experiment(pca, shapes, {}, progress.callback());
      if (!c.ok()) return print_error(cancel_requested() ? cancelled_status() : c.status());
      compression = std::move(c).value();
    }
  }
  progress.finish();
  const auto r = static_cast<int>(pca.components.size());
  const std::size_t n = shapes.size();

  OutputFiles files;
  auto add_mesh = [&](const std::string& name, const TriMesh& m) -> Status {
    SPHEREKIT_ASSIGN_OR_RETURN(std::string text, mesh_obj_text(m));
    files.add(name, std::move(text));
    return Status();
  };
  if (Status s = add_mesh("mean.obj", TriMesh{pca.mean, pca.F}); !s.ok()) return print_error(s);
  // Components shown as the mean moved by +-2 standard deviations (Fig. 1 adds them to the
  // average); the glTF holds them at one standard deviation as morph targets.
  std::vector<TriMesh> gltf_members{TriMesh{pca.mean, pca.F}};
  std::vector<std::string> names{"mean"};
  for (int j = 0; j < r; ++j) {
    const RowMat3d d = pca.sigma[static_cast<std::size_t>(j)] * pca.components[static_cast<std::size_t>(j)];
    if (Status s = add_mesh(strprintf("pc%d_plus.obj", j + 1), TriMesh{pca.mean + 2 * d, pca.F}); !s.ok()) return print_error(s);
    if (Status s = add_mesh(strprintf("pc%d_minus.obj", j + 1), TriMesh{pca.mean - 2 * d, pca.F}); !s.ok()) return print_error(s);
    gltf_members.push_back(TriMesh{pca.mean + d, pca.F});
    names.push_back(strprintf("pc%d", j + 1));
  }
  convert::GltfMorphOptions g;
  g.name = "pca";
  g.names = names;
  g.provenance.sphere_map = a.dir;
  auto glb = convert::build_gltf_morph_targets(gltf_members, g);
  if (!glb.ok()) return print_error(glb.status());
  files.add("pca.glb", glb->glb);

  // The error table: CSV (one row per k) and JSON.
  std::string csv = "components";
  for (const Member& m : members.value()) csv += ",rms_" + m.name;
  for (const Member& m : members.value()) csv += ",psnr_" + m.name;
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
  if (!png.ok()) return print_error(png.status());
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
                                                  : (p.bits == 0 ? std::string("PCA float32") : strprintf("PCA %d-bit", p.bits));
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
    if (!cpng.ok()) return print_error(cpng.status());
    files.add("compression.png", std::move(cpng).value());
  }

  Json rep;
  rep["command"] = "pca";
  rep["collection"] = a.dir;
  rep["size"] = a.size;
  rep["members"] = Json::array();
  for (std::size_t i = 0; i < n; ++i)
    rep["members"].push_back({{"name", members.value()[i].name}, {"peak", table.peak[i]},
                              {"coefficients", std::vector<double>(pca.coefficients.row(static_cast<Eigen::Index>(i)).data(),
                                                                   pca.coefficients.row(static_cast<Eigen::Index>(i)).data() + r)}});
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
  if (Status s = write_output_folder(a.output, kPcaReport, files); !s.ok()) return print_error(s);

  if (!a.quiet) {
    std::printf("PCA of %zu members (%lld vertices each): %d components\n", n, static_cast<long long>(pca.mean.rows()), r);
    Table t({"components", "mean RMS", "max RMS", "mean PSNR dB", "variance"});
    double cumulative = 0;
    for (int k = 0; k <= r; ++k) {
      if (k > 0) cumulative += pca.variance_fraction[static_cast<std::size_t>(k - 1)];
      const auto kk = static_cast<std::size_t>(k);
      t.add_row({std::to_string(k), strprintf("%.3g", table.mean_rms[kk]), strprintf("%.3g", table.max_rms[kk]),
                 std::isfinite(table.mean_psnr[kk]) ? strprintf("%.1f", table.mean_psnr[kk]) : "inf",
                 strprintf("%.1f%%", 100 * cumulative)});
    }
    t.print();
    if (!compression.empty()) {
      Table c({"method", "k", "bits", "bytes/shape", "deflated", "mean PSNR dB"});
      for (const convert::CompressionPoint& p : compression)
        c.add_row({p.method, p.method == "pca" ? std::to_string(p.components) : "-", p.bits ? std::to_string(p.bits) : "f32",
                   strprintf("%.0f", p.bytes_per_shape), strprintf("%.0f", p.deflated_bytes_per_shape),
                   std::isfinite(p.mean_psnr) ? strprintf("%.1f", p.mean_psnr) : "inf"});
      c.print();
    }
    std::printf("wrote %s\n", a.output.c_str());
  }
  return 0;
}

}  // namespace

int run_pca_job(const std::string& dir, const std::string& output, bool quiet) {
  PcaArgs a;
  a.dir = dir;
  a.output = output;
  a.quiet = quiet;
  return run_pca(a);
}

void register_pca(CLI::App& app) {
  auto args = std::make_shared<PcaArgs>();
  CLI::App* cmd = add_command(
      app, "pca", "Average shape and principal components of a collection, error and compression tables",
      "Every member of the collection DIR is remeshed through its geometry image (--size; the\n"
      "remeshes share one connectivity and their vertices correspond) and the remeshes' PCA is\n"
      "taken (paper Fig. 1). Writes the folder OUT: mean.obj, pcK_plus.obj / pcK_minus.obj (the\n"
      "mean +- 2 standard deviations along component K), pca.glb (base = mean, one morph target\n"
      "per component at one standard deviation), pca_errors.csv and pca_errors.png (RMS vertex\n"
      "error and PSNR of every member reconstructed from 0..r components), compression.csv and\n"
      "compression.png (bytes per shape versus error: the PCA model at float32 / 16 / 12 bits\n"
      "against Draco on each remesh alone at 8..16 bits) and pca.json with everything. OUT is\n"
      "replaced only when it is empty or a previous pca output.",
      "  spherekit pca cats -o cats_pca\n"
      "  spherekit pca heads -o heads_pca --size 129 --no-compression");
  cmd->add_option("DIR", args->dir, "collection folder")->required();
  cmd->add_option("-o,--output", args->output, "output folder")->required();
  cmd->add_option("--size", args->size, "geometry-image size of the remeshes, 2^k+1")->capture_default_str();
  cmd->add_flag("--no-compression", args->no_compression, "skip the compression experiment");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing but errors");
  cmd->callback([args] { set_exit_code(run_pca(*args)); });
}

}  // namespace spherekit::cli
