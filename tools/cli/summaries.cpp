// The summaries of the jobs' results as the commands print them; `run` prints the same ones
// for its stages. Results go to stdout, per-member progress lines and warnings to stderr.
#include <cmath>
#include <cstdio>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "spherekit/pipeline/apps.h"
#include "spherekit/pipeline/collection.h"
#include "spherekit/pipeline/convert.h"
#include "spherekit/scheduler/collection_plan.h"

namespace spherekit::cli {
namespace {

std::string db_text(const Json& x) { return x.is_number() ? format_text("%.1f", x.get<double>()) : std::string("inf"); }

}  // namespace

void print_check_summary(const pipeline::LoadedMesh& m, const Status& verdict) {
  const MeshCheck& c = m.check;
  const formats::ReadInfo& info = m.info;
  const std::string& path = m.path;
  std::printf("%s: %d vertices, %d faces, %d edges\n", path.c_str(), c.vertices, c.faces, c.edges);
  if (info.polygons_triangulated > 0)
    std::printf("  file faces %lld: %lld triangles, %lld quads, %lld n-gons (polygons triangulated)\n",
                static_cast<long long>(info.faces.faces), static_cast<long long>(info.faces.triangles),
                static_cast<long long>(info.faces.quads), static_cast<long long>(info.faces.ngons));
  std::printf("  components %d, boundary loops %d, Euler %d, genus %d, orientable %s\n", c.components,
              c.boundary_loops, c.euler, c.genus, c.orientable ? "yes" : "no");
  std::printf("  non-manifold edges %d, non-manifold vertices %d, orientation conflicts %d\n", c.nonmanifold_edges,
              c.nonmanifold_vertices, c.orientation_conflicts);
  std::printf("  faces: %d degenerate, %d duplicate, %d zero-area, %d invalid indices\n", c.degenerate_faces,
              c.duplicate_faces, c.zero_area_faces, c.invalid_indices);
  std::printf("  vertices: %d unreferenced, %d non-finite; bbox diagonal %.6g\n", c.unreferenced_vertices,
              c.nonfinite_vertices, c.bbox_diag);
  if (verdict.ok())
    std::printf("  ok: genus-0 (%d hole%s)\n", c.boundary_loops, c.boundary_loops == 1 ? "" : "s");
  else
    std::printf("  not accepted: %s\n", verdict.message().c_str());
}

void print_mesh_summary(const pipeline::ConvertMeshResult& r) {
  const pipeline::ConvertMeshJob& a = r.job;
  const pipeline::GeometryAssets& g = r.assets;
  std::printf("%s + %s -> %s (%d x %d octahedral)\n", a.mesh.c_str(), a.sphere.c_str(), a.output.c_str(), a.options.size,
              a.options.size);
  std::printf("  %lld vertices, %lld faces; remesh %lld vertices, %lld faces; %d texel%s in holes\n", r.vertices, r.faces,
              static_cast<long long>(g.remesh.V.rows()), static_cast<long long>(g.remesh.F.rows()),
              g.image.texels_in_holes, g.image.texels_in_holes == 1 ? "" : "s");
  std::printf("  previews %s, %s\n", g.previews.at(0).c_str(), g.previews.at(1).c_str());
  if (g.measured) {
    std::printf("  PSNR %.2f dB (rms %.3g, max %.3g, bbox diagonal %.4g)\n", g.error.psnr, g.error.rms,
                g.error.max_distance, g.error.peak);
    if (g.error_all_faces)
      std::printf("  (remesh faces spanning the holes left out; with them: PSNR %.2f dB)\n", g.error_all_faces->psnr);
  }
  if (a.options.lods > 0) {
    const convert::DracoQuantization& q = g.lods.quantization.quantization;
    std::printf("  glTF (Draco, %d/%d/%d bits position/normal/texcoord%s):\n", q.position_bits, q.normal_bits,
                q.texcoord_bits, g.lods.quantization.reference_rms_error > 0 ? ", from the error budget" : "");
    for (std::size_t k = 0; k < g.lods.levels.size(); ++k) {
      const convert::GltfLodLevel& level = g.lods.levels[k];
      std::printf("    %s  %3d x %-3d %8lld points %8lld faces %10llu bytes", g.lod_paths.levels[k].c_str(),
                  level.image_size, level.image_size, static_cast<long long>(level.primitive.decoded.mesh.V.rows()),
                  static_cast<long long>(level.primitive.decoded.mesh.F.rows()),
                  static_cast<unsigned long long>(file_bytes(g.lod_paths.levels[k])));
      if (k < g.lod_errors.size()) std::printf("  PSNR %.2f dB", g.lod_errors[k].psnr);
      std::printf("\n");
    }
    std::printf("    %s  all levels (MSFT_lod) %llu bytes\n", g.lod_paths.combined.c_str(),
                static_cast<unsigned long long>(file_bytes(g.lod_paths.combined)));
  }
  if (g.cage) {
    const pipeline::CageAssets& c = *g.cage;
    std::printf("  cage %s: %d quads, %d control points (fit rms %.3g); %s displacement %d x %d per quad -> %s",
                c.cage_path.c_str(), c.quads, c.control_points, c.fit_rms, pipeline::displacement_kind_name(c.kind), c.tile,
                c.tile, c.displacement_path.c_str());
    if (c.measured)
      std::printf("\n    PSNR limit surface %.2f dB, displaced %.2f dB (%lld floats stored)", c.limit_error.psnr,
                  c.displaced_error.psnr, c.stored_floats);
    std::printf("  %.2f s\n", c.seconds);
  }
  std::printf("  time: read %.2f s, sample %.3f s, remesh %.3f s, write %.2f s, PSNR %.2f s, %stotal %.2f s\n",
              r.read_seconds, g.times.sample, g.times.remesh, g.times.write, g.times.psnr,
              a.options.lods > 0 ? format_text("glTF %.2f s + PSNR %.2f s, ", g.times.gltf, g.times.gltf_psnr).c_str() : "",
              r.wall_seconds);
}

void print_collection_summary(const pipeline::ConvertCollectionResult& r) {
  const pipeline::ConvertOptions& o = r.job.options;
  for (const pipeline::ConvertedMember& m : r.members) {
    std::fprintf(stderr, "  %-24s %d x %d", m.name.c_str(), o.size, o.size);
    if (m.assets.measured) std::fprintf(stderr, "  PSNR %.2f dB", m.assets.error.psnr);
    if (m.assets.cage && m.assets.cage->measured && std::isfinite(m.assets.cage->displaced_error.psnr))
      std::fprintf(stderr, "  cage+displacement %.2f dB", m.assets.cage->displaced_error.psnr);
    std::fprintf(stderr, "  %.1f s\n", m.seconds);
  }
  std::printf("%s -> %s: %zu members, %d x %d octahedral images%s%s, %.1f s\n", r.job.collection.c_str(),
              r.job.output.c_str(), r.members.size(), o.size, o.size,
              o.lods > 0 ? format_text(", %d glTF LODs", o.lods).c_str() : "",
              o.cage > 0 ? format_text(", cage %d + %s displacement", o.cage, pipeline::displacement_kind_name(o.displacement)).c_str() : "",
              r.wall_seconds);
  if (r.lod_connectivity == "template")
    std::fprintf(stderr, "  LODs: %s's mesh laid on every member (one connectivity per level)\n", r.lod_template.c_str());
  else if (!r.lod_connectivity_reason.empty())
    std::fprintf(stderr, "  LODs: the common remesh simplified, because %s\n", r.lod_connectivity_reason.c_str());
}

void print_collection_warning(const pipeline::MakeCollectionResult& r) {
  for (const std::string& w : r.landmark_warnings) std::fprintf(stderr, "spherekit: warning: %s\n", w.c_str());
  if (!r.refinement_warning.empty())
    std::fprintf(stderr, "spherekit: warning: step 6 failed (%s); the collection keeps the step-2 maps (locations from the reference)\n",
                 r.refinement_warning.c_str());
}

void print_submit_plan(const scheduler::CollectionPlanOptions& o, int k_memory, double joint_memory_mb, int remesh,
                       const std::string& scheduler_name) {
  const int n = static_cast<int>(o.meshes.size()), k = static_cast<int>(o.subset.size());
  std::string names;
  for (int i : o.subset) names += (names.empty() ? "" : " ") + o.names[static_cast<size_t>(i)];
  std::fprintf(stderr,
               "submit: %d members; F from %d (%s), joint-step quadrics %.0f MB (k <= %d fit in %.0f MB); "
               "%d maps as independent tasks; scheduler %s; plan %s/plan.json\n",
               n, k, names.c_str(), scheduler::joint_quadric_bytes(k, remesh) / (1024 * 1024), k_memory,
               joint_memory_mb, n - k, scheduler_name.c_str(), o.work_dir.c_str());
}

void print_add_summary(const pipeline::AddToCollectionResult& r, const pipeline::AddToCollectionJob& job) {
  if (r.registered) {
    std::printf("%s -> %s (registered; %zu features on the collection's locations)\n", job.mesh.c_str(),
                r.map_path.c_str(), r.features);
    std::printf("  efficiency %.4f, max feature error %.2g rad\n", r.map.efficiency, r.map.max_feature_angle);
    return;
  }
  const ConstrainedParamResult& m = r.map;
  std::printf("%s -> %s (%zu features on the collection's locations)\n", job.mesh.c_str(), r.map_path.c_str(), r.features);
  std::printf("  efficiency %.4f, flipped faces %d, max feature error %.2g rad, %d paths, %d Steiner vertices\n",
              m.efficiency, m.flipped_faces, m.max_feature_angle, m.network.paths, m.network.steiner_vertices);
  if (m.efficiency_retried)
    std::printf("  made again as the unconstrained stage would (the first map's efficiency %.4f was below the retry bar)%s\n",
                m.first_efficiency, m.as_unconstrained ? "" : "; the first kept");
  std::printf("  time %.2f s (wall %.2f s), peak memory %.0f MB\n", m.times.total, r.wall_seconds, peak_rss_mb());
}

void print_consistent_summary(const pipeline::MakeCollectionResult& c, const std::string& output, double wall_seconds) {
  const ConsistentParamResult& r = c.maps;
  const bool refined = c.manifest.options.value("refine_locations", true);
  const std::string& reference = c.members[static_cast<size_t>(c.reference)].name;
  std::printf("collection %s: %zu meshes, %zu features (%s)\n", output.c_str(), c.members.size(), c.feature_names.size(),
              refined && r.refinement_failure.empty() ? "locations from all meshes" : "locations from the reference only");
  Table steps({"step", "work", "time (s)"});
  steps.add_row({"1", "unconstrained map of " + reference, format_text("%.2f", r.times.reference)});
  steps.add_row({"2", format_text("constrained maps of %zu meshes to F'", c.members.size() - 1), format_text("%.2f", r.times.initial)});
  if (refined && c.members.size() > 1) {
    const int grid = c.manifest.options.value("remesh_size", 0);
    steps.add_row({"3", format_text("remesh %d x %d, features snapped", grid, grid), format_text("%.2f", r.times.remesh)});
    steps.add_row({"4", format_text("concatenate: %d vertices in R^%zu", r.remesh_vertices, 3 * c.members.size()),
                   format_text("%.2f", r.times.concatenate)});
    steps.add_row({"5", format_text("joint unconstrained map (efficiency %.4f)", r.joint_efficiency), format_text("%.2f", r.times.joint)});
    steps.add_row({"6", format_text("constrained maps of %zu meshes to F", c.members.size()), format_text("%.2f", r.times.final_maps)});
  }
  steps.add_row({"", "total", format_text("%.2f", r.times.total)});
  steps.print();
  std::printf("\n");
  // "of own": the map's efficiency over its mesh's unconstrained map's ("retried": made again
  // as the unconstrained stage would, ConsistentParamOptions::efficiency_retry).
  Table t({"mesh", "V", "efficiency", "of own", "flips", "feature err (rad)", "paths", "path len", "max len/geo", "Steiner",
           "time (s)"});
  for (size_t i = 0; i < c.members.size(); ++i) {
    const auto& m = r.maps[i];
    const double own = i < r.unconstrained_efficiency.size() ? r.unconstrained_efficiency[i] : 0.0;
    std::string of_own = own > 0 ? format_text("%.2fx", m.efficiency / own) : "-";
    if (m.efficiency_retried) of_own += " retried";
    t.add_row({c.members[i].name, std::to_string(c.members[i].mesh.V.rows()), format_text("%.4f", m.efficiency), of_own,
               std::to_string(m.flipped_faces), format_text("%.1e", m.max_feature_angle), std::to_string(m.network.paths),
               format_text("%.4g", m.network.total_length), format_text("%.2f", m.network.max_ratio),
               std::to_string(m.network.steiner_vertices), format_text("%.2f", m.times.total)});
  }
  t.print();
  std::printf("wall %.2f s, CPU %.2f s, peak memory %.0f MB\n", wall_seconds, cpu_seconds(), peak_rss_mb());
}

void print_transfer_summary(const pipeline::TransferResult& r, const pipeline::TransferJob& job) {
  std::printf("transfer %s: %s -> %s: %s (%lld vertices", pipeline::transfer_what_name(job.what), r.from.c_str(),
              r.to.c_str(), job.output.c_str(), r.vertices);
  if (r.vertices_in_holes) std::printf(", %d in holes of %s", r.vertices_in_holes, r.from.c_str());
  std::printf(")\n");
}

void print_morph_summary(const pipeline::MorphResult& r, const pipeline::MorphJob& job) {
  std::printf("morph %s -> %s: %d frames of %lld vertices (%s) in %s\n", r.a.c_str(), r.b.c_str(), job.frames, r.vertices,
              r.aligned ? format_text("aligned: scale %.3f, rotation %.1f deg", r.scale, r.rotation_deg).c_str() : "not aligned",
              job.output.c_str());
}

void print_pca_summary(const pipeline::PcaResult& result, const pipeline::PcaJob& job) {
  const Json& rep = result.report;
  std::printf("PCA of %zu members (%lld vertices each): %d components\n", rep["members"].size(),
              rep["vertices"].get<long long>(), rep["components"].get<int>());
  Table t({"components", "mean RMS", "max RMS", "mean PSNR dB", "variance"});
  double cumulative = 0;
  for (const Json& e : rep["errors"]) {
    const int k = e["components"].get<int>();
    if (k > 0) cumulative += rep["variance_fraction"][static_cast<std::size_t>(k - 1)].get<double>();
    t.add_row({std::to_string(k), format_text("%.3g", e["mean_rms"].get<double>()), format_text("%.3g", e["max_rms"].get<double>()),
               db_text(e["mean_psnr_db"]), format_text("%.1f%%", 100 * cumulative)});
  }
  t.print();
  if (!rep["compression"].empty()) {
    Table c({"method", "k", "bits", "bytes/shape", "deflated", "mean PSNR dB"});
    for (const Json& p : rep["compression"]) {
      const int bits = p["bits"].get<int>();
      c.add_row({p["method"].get<std::string>(), p["method"] == "pca" ? std::to_string(p["components"].get<int>()) : "-",
                 bits ? std::to_string(bits) : "f32", format_text("%.0f", p["bytes_per_shape"].get<double>()),
                 format_text("%.0f", p["deflated_bytes_per_shape"].get<double>()), db_text(p["mean_psnr_db"])});
    }
    c.print();
  }
  std::printf("wrote %s\n", job.output.c_str());
}

}  // namespace spherekit::cli
