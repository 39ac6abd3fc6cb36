// `spherekit convert --collection DIR -o OUT`: every member of a consistent collection through
// the same converter, into one folder written all-or-nothing. Consistent maps put corresponding
// surface points at the same sphere point, so every output shares one layout across members
// (same texel, same cage vertex, same glTF vertex = same place): the report records, per
// feature, the texel that holds it and how far each member's texel lies from its own feature
// vertex, and the members are also written as one glTF with morph targets.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "collection.h"
#include "convert_common.h"
#include "member_io.h"
#include "spherekit/convert/geometry_image_exr.h"
#include "spherekit/convert/gltf_lods.h"
#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/convert/gltf_morph.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/metrics.h"
#include "spherekit/version.h"

namespace fs = std::filesystem;

namespace spherekit::cli {
namespace {

constexpr const char* kConvertReport = "convert_report.json";

// The texel (row, column) of an n x n octahedral image nearest to sphere point p.
std::pair<int, int> nearest_texel(const Eigen::Vector3d& p, int n) {
  const Eigen::Vector2d uv = sphere_to_octahedral(p);
  const int j = static_cast<int>(std::lround((uv.x() + 1) / 2 * (n - 1)));
  const int i = static_cast<int>(std::lround((uv.y() + 1) / 2 * (n - 1)));
  return {std::clamp(i, 0, n - 1), std::clamp(j, 0, n - 1)};
}

struct MemberOutput {
  std::string name;
  GeometryImage image;
  RemeshError error;
  Json json;
};

}  // namespace

int run_convert_collection(const ConvertArgs& a) {
  if (Status s = check_convert_flags(a); !s.ok()) return print_error(s);
  Stopwatch wall;
  auto info = read_collection(a.collection);
  if (!info.ok()) return print_error(info.status());
  if (Status s = require_staged_folder_target(a.output, kConvertReport); !s.ok()) return print_error(s);
  if (!a.report.empty())
    if (Status s = require_output_folders({a.report}); !s.ok()) return print_error(s);
  auto loaded = load_all_members(info.value());
  if (!loaded.ok()) return print_error(loaded.status());
  std::vector<Member>& members = loaded.value();
  // Every map must be a bijection before any work (as for one mesh).
  for (const Member& m : members)
    if (const int flipped = count_flipped_faces(m.mesh.F, m.map.S); flipped != 0)
      return print_error(Status(ErrorCode::InvalidInput,
                                strprintf("%s: map of %s has %d flipped or degenerate faces on the sphere",
                                          a.collection.c_str(), m.name.c_str(), flipped)));

  const std::vector<Eigen::Vector3d>& F = info->locations;
  Json report;
  std::vector<MemberOutput> outputs;
  Status written = write_staged_folder(a.output, kConvertReport, [&](const std::string& dir) -> Status {
    for (std::size_t k = 0; k < members.size(); ++k) {
      const Member& m = members[k];
      if (cancel_requested()) return cancelled_status();
      MemberOutput out;
      out.name = m.name;
      Json& j = out.json;
      j["name"] = m.name;
      j["source"] = m.source;
      j["V"] = m.mesh.V.rows();
      j["F"] = m.mesh.F.rows();
      Stopwatch t;
      auto sampled = sample_geometry_image(m.mesh, m.map.S, a.size, geometry_image_options(a));
      if (!sampled.ok()) return with_file(sampled.status(), m.source);
      out.image = std::move(sampled).value();
      const std::string exr = m.name + ".exr";
      SPHEREKIT_RETURN_IF_ERROR(convert::write_geometry_image_exr((fs::path(dir) / exr).string(), out.image,
                                                                  {m.source, (fs::path(info->dir) / (m.name + ".sphere.obj")).string()}));
      j["image"] = {{"file", exr}, {"bytes", file_bytes((fs::path(dir) / exr).string())},
                    {"texels_in_holes", out.image.texels_in_holes}};
      {
        auto previews = write_geometry_image_previews(out.image, (fs::path(dir) / m.name).string());
        if (!previews.ok()) return previews.status();
        Json names = Json::array();
        for (const std::string& p : previews.value()) names.push_back(fs::path(p).filename().string());
        j["image"]["previews"] = std::move(names);
      }
      if (a.psnr_samples > 0) {
        RemeshErrorOptions opts;
        opts.samples = a.psnr_samples;
        out.error = remesh_error(m.mesh, geometry_image_mesh(out.image), opts, geometry_image_hole_faces(out.image));
        j["image"]["psnr_db"] = number_or_null(out.error.psnr);
      }
      if (a.lods > 0) {
        convert::GltfLodOptions opts;
        opts.levels = a.lods;
        opts.budget = a.budget;
        opts.reference_rms_error = a.psnr_samples > 0 ? out.error.rms : 0;
        opts.name = m.name;
        opts.provenance = {m.source, info->dir};
        // Hole faces stay: every member's levels share one connectivity.
        auto level_images = convert::lod_geometry_images(m.mesh, m.map.S, out.image, a.lods, geometry_image_options(a));
        if (!level_images.ok()) return with_file(level_images.status(), m.source);
        auto built = convert::build_gltf_lods(level_images.value(), opts);
        if (!built.ok()) return built.status();
        auto paths = convert::write_gltf_lods((fs::path(dir) / m.name).string(), built.value());
        if (!paths.ok()) return paths.status();
        Json levels = Json::array();
        for (std::size_t l = 0; l < paths->levels.size(); ++l)
          levels.push_back({{"file", fs::path(paths->levels[l]).filename().string()},
                            {"bytes", file_bytes(paths->levels[l])},
                            {"size", built->levels[l].image_size}});
        j["lods"] = std::move(levels);
        j["lods_file"] = fs::path(paths->combined).filename().string();
      }
      if (a.cage > 0) {
        auto cage = build_cage(m.mesh, m.map.S, a, (fs::path(dir) / m.name).string(), {});
        if (!cage.ok()) return with_file(cage.status(), m.source);
        Json c = cage_json(cage.value());
        c["file"] = fs::path(cage->cage_path).filename().string();
        c["displacement_file"] = fs::path(cage->displacement_path).filename().string();
        j["cage"] = std::move(c);
      }
      j["seconds"] = t.seconds();
      if (!a.quiet) {
        std::fprintf(stderr, "  %-24s %d x %d", m.name.c_str(), a.size, a.size);
        if (a.psnr_samples > 0) std::fprintf(stderr, "  PSNR %.2f dB", out.error.psnr);
        if (a.cage > 0 && j["cage"].contains("psnr_db") && j["cage"]["psnr_db"].is_number())
          std::fprintf(stderr, "  cage+displacement %.2f dB", j["cage"]["psnr_db"].get<double>());
        std::fprintf(stderr, "  %.1f s\n", j["seconds"].get<double>());
      }
      outputs.push_back(std::move(out));
    }

    // One glTF with every member as a morph target of the first: possible only because the
    // consistent images share their texels, hence their vertices and faces.
    if (outputs.size() >= 2) {
      std::vector<convert::GltfMesh> meshes;
      std::vector<std::string> names;
      for (const MemberOutput& o : outputs) {
        auto g = convert::gltf_mesh_from_geometry_image(o.image);
        if (!g.ok()) return g.status();
        meshes.push_back(std::move(g).value());
        names.push_back(o.name);
      }
      convert::GltfMorphOptions mo;
      mo.names = names;
      mo.provenance = {a.collection, info->dir};
      auto morph = convert::build_gltf_morph_targets(meshes, mo);
      if (!morph.ok()) return morph.status();
      const std::string path = (fs::path(dir) / "collection_morph.glb").string();
      SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic(path, morph->glb));
      report["morph"] = {{"file", "collection_morph.glb"}, {"bytes", morph->glb.size()}, {"targets", morph->targets}};
    }

    // Feature texels: the texel nearest each final location F_k, and per member the distance
    // from the image's point there to the member's own feature vertex, relative to the largest
    // distance from that texel to its 8 neighbours (the local sample spacing): consistent maps
    // keep every ratio near or below 1.
    Json feats = Json::array();
    const int n = a.size;
    for (std::size_t f = 0; f < F.size(); ++f) {
      const auto [ti, tj] = nearest_texel(F[f], n);
      Json e;
      e["name"] = info->feature_names[f];
      e["texel"] = {ti, tj};
      Json per = Json::array();
      for (std::size_t k = 0; k < outputs.size(); ++k) {
        const Member& m = members[k];
        if (m.features.rows() != static_cast<Eigen::Index>(F.size())) {
          per.push_back(nullptr);
          continue;
        }
        const Eigen::Vector3d p = outputs[k].image.position(ti, tj).cast<double>();
        double spacing = 0;
        for (int di = -1; di <= 1; ++di)
          for (int dj = -1; dj <= 1; ++dj) {
            const int i2 = ti + di, j2 = tj + dj;
            if (i2 < 0 || j2 < 0 || i2 >= n || j2 >= n) continue;
            spacing = std::max(spacing, (outputs[k].image.position(i2, j2).cast<double>() - p).norm());
          }
        const double d = (p - m.features.row(static_cast<Eigen::Index>(f)).transpose()).norm();
        per.push_back({{"member", m.name}, {"distance", d}, {"texel_spacing", spacing}});
      }
      e["members"] = std::move(per);
      feats.push_back(std::move(e));
    }
    report["feature_texels"] = std::move(feats);
    report["collection"] = fs::absolute(a.collection).lexically_normal().string();
    report["size"] = a.size;
    report["positions"] = a.positions;
    report["layout"] = "octahedral";
    Json list = Json::array();
    for (MemberOutput& o : outputs) list.push_back(std::move(o.json));
    report["members"] = std::move(list);
    if (a.cage > 0) report["cage"] = {{"n", a.cage}, {"tile", a.cage_tile}, {"displacement", a.displacement}};
    report["lods"] = a.lods;
    report["version"] = kVersion;
    report["times"]["wall"] = wall.seconds();
    return write_json_atomic((fs::path(dir) / kConvertReport).string(), report);
  });
  if (!written.ok()) return print_error(written);
  if (!a.report.empty())
    if (Status s = write_json_atomic(a.report, report); !s.ok()) return print_error(s);
  if (!a.quiet)
    std::printf("%s -> %s: %zu members, %d x %d octahedral images%s%s, %.1f s\n", a.collection.c_str(),
                a.output.c_str(), members.size(), a.size, a.size,
                a.lods > 0 ? strprintf(", %d glTF LODs", a.lods).c_str() : "",
                a.cage > 0 ? strprintf(", cage %d + %s displacement", a.cage, a.displacement.c_str()).c_str() : "",
                wall.seconds());
  return 0;
}

}  // namespace spherekit::cli
