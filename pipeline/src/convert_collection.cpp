// convert_collection(): every member of a consistent collection through the same pipeline,
// into one folder written all-or-nothing (convert.h). Consistent maps put corresponding
// surface points at the same sphere point, so every output shares one layout across members
// (same texel, same cage vertex, same glTF vertex = same place): the report records, per
// feature, the texel that holds it and how far each member's texel lies from its own feature
// vertex, and the members are also written as one glTF with morph targets.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/convert/gltf_morph.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/pipeline/convert.h"
#include "spherekit/pipeline/json.h"
#include "spherekit/version.h"
#include "stopwatch.h"

namespace fs = std::filesystem;

namespace spherekit::pipeline {
namespace {

// A laid template that folds over on more than this share of its faces on some member is not
// even tried (see template_or_remesh_levels): a folded face is a hole and a fin in that
// member's levels.
constexpr double kMaxTemplateFolds = 0.05;
// Points sampled per direction for each PSNR of that choice (2 candidates x members x levels
// of them; the candidates differ by several dB where it matters, see template_or_remesh_levels).
constexpr int kChoiceSamples = 20000;

// Per level, the worst member's PSNR of `lods` (each decoded level against the member's mesh).
std::vector<double> worst_member_psnr(const std::vector<formats::LoadedMember>& members,
                                      const std::vector<convert::GltfLods>& lods, const RemeshErrorOptions& psnr) {
  std::vector<double> worst(lods[0].levels.size(), std::numeric_limits<double>::infinity());
  for (std::size_t k = 0; k < members.size(); ++k)
    for (std::size_t l = 0; l < worst.size(); ++l) {
      const auto& d = lods[k].levels[l].primitive.decoded.mesh;
      worst[l] = std::min(worst[l], remesh_error(members[k].mesh, TriMesh{d.V, d.F}, psnr).psnr);
    }
  return worst;
}

double mean_of(const std::vector<double>& x) {
  double s = 0;
  for (double v : x) s += v;
  return x.empty() ? 0.0 : s / static_cast<double>(x.size());
}

// A collection's levels under LodMode::Original: the template member's mesh laid on every
// member (template_lods.h), or the common remesh's levels (adaptive_lods.h), whichever has the
// higher mean over the levels of the worst member's PSNR (decoded, against the members'
// meshes): every level is shown to someone, and a level is only as good as its worst member.
// The laid template is exact on the template, but where the consistent maps do not agree at
// its triangle scale its triangles fold over on a member (TOSCA cat0 on cat2: 2.4% of its
// faces, worst member per level 51.8/50.8/46.2/29.0 dB against the remesh's
// 68.0/58.5/47.4/23.1); the remesh's levels keep the faces spanning the members' openings (ICT
// heads: 31.2/26.9/26.9/26.9 dB, laid 54.9/54.7/52.9/45.7), and on the FAUST bodies its coarse
// levels fall apart (66.9/35.9/33.4/33.3 dB, laid 56.4/54.1/46.9/34.8). A template folding on
// more than kMaxTemplateFolds of its faces is not tried. result: lod_connectivity and its record.
Result<std::vector<convert::GltfLods>> template_or_remesh_levels(const std::vector<formats::LoadedMember>& members,
                                                                  int lod_template, const std::vector<GeometryImage>& images,
                                                                  std::vector<convert::GltfLodOptions> lod_options,
                                                                  const ConvertOptions& o, const ProgressFn& progress,
                                                                  ConvertCollectionResult& result) {
  std::vector<convert::TemplateLodMember> tm;
  for (const formats::LoadedMember& m : members) tm.push_back({&m.mesh, &m.map.S});
  SPHEREKIT_ASSIGN_OR_RETURN(convert::TemplateLayout layout, convert::lay_template(tm, lod_template));
  Json folds = Json::object();
  double worst_fold = 0;
  std::string worst_name;
  for (std::size_t k = 0; k < members.size(); ++k) {
    const double share = layout.faces > 0 ? static_cast<double>(layout.folded_faces[k]) / layout.faces : 0.0;
    folds[members[k].name] = {{"folded_faces", layout.folded_faces[k]}, {"share", share},
                              {"vertices_over_holes", layout.outside_vertices[k]}};
    if (share > worst_fold) worst_fold = share, worst_name = members[k].name;
  }
  result.lod_template_folds = std::move(folds);
  result.lod_template = members[static_cast<std::size_t>(lod_template)].name;
  std::vector<convert::GltfLodOptions> remesh_options = lod_options;
  for (convert::GltfLodOptions& lo : remesh_options) lo.mode = convert::LodMode::Adaptive;
  SPHEREKIT_ASSIGN_OR_RETURN(std::vector<convert::GltfLods> remesh,
                             convert::build_consistent_gltf_lods(images, remesh_options, progress));
  char why[256];
  if (worst_fold > kMaxTemplateFolds) {
    std::snprintf(why, sizeof why, "the template %s laid on %s folds over on %.1f%% of its faces", result.lod_template.c_str(),
                  worst_name.c_str(), 100 * worst_fold);
    result.lod_connectivity = "remesh";
    result.lod_connectivity_reason = why;
    return remesh;
  }
  for (convert::GltfLodOptions& lo : lod_options) lo.lod0_max_vertices = 0;  // the template's count
  SPHEREKIT_ASSIGN_OR_RETURN(std::vector<convert::GltfLods> laid,
                             convert::build_template_gltf_lods(layout, tm, o.size, lod_options, progress));
  RemeshErrorOptions psnr;
  psnr.samples = kChoiceSamples;
  psnr.threads = o.threads;
  const std::vector<double> laid_psnr = worst_member_psnr(members, laid, psnr);
  const std::vector<double> remesh_psnr = worst_member_psnr(members, remesh, psnr);
  result.lod_choice = {{"template_worst_member_psnr_db", laid_psnr}, {"remesh_worst_member_psnr_db", remesh_psnr}};
  if (mean_of(laid_psnr) >= mean_of(remesh_psnr)) {
    result.lod_connectivity = "template";
    return laid;
  }
  std::snprintf(why, sizeof why,
                "the template %s laid on every member has a worst member of %.1f dB over the levels (mean), the remesh %.1f dB",
                result.lod_template.c_str(), mean_of(laid_psnr), mean_of(remesh_psnr));
  result.lod_connectivity = "remesh";
  result.lod_connectivity_reason = why;
  return remesh;
}

// The texel (row, column) of an n x n octahedral image nearest to sphere point p.
std::pair<int, int> nearest_texel(const Eigen::Vector3d& p, int n) {
  const Eigen::Vector2d uv = sphere_to_octahedral(p);
  const int j = static_cast<int>(std::lround((uv.x() + 1) / 2 * (n - 1)));
  const int i = static_cast<int>(std::lround((uv.y() + 1) / 2 * (n - 1)));
  return {std::clamp(i, 0, n - 1), std::clamp(j, 0, n - 1)};
}

std::string file_name(const std::string& path) { return fs::path(path).filename().string(); }

Json member_json(const ConvertedMember& m, const ConvertOptions& o, const std::string& dir) {
  const GeometryAssets& g = m.assets;
  Json j;
  j["name"] = m.name;
  j["source"] = m.source;
  j["V"] = m.vertices;
  j["F"] = m.faces;
  const std::string exr = m.name + ".exr";
  j["image"] = {{"file", exr}, {"bytes", file_bytes((fs::path(dir) / exr).string())},
                {"texels_in_holes", g.image.texels_in_holes}};
  Json previews = Json::array();
  for (const std::string& p : g.previews) previews.push_back(file_name(p));
  j["image"]["previews"] = std::move(previews);
  if (g.measured) j["image"]["psnr_db"] = number_or_null(g.error.psnr);
  if (o.lods > 0) {
    Json levels = Json::array();
    for (std::size_t l = 0; l < g.lod_paths.levels.size(); ++l) {
      Json level{{"file", file_name(g.lod_paths.levels[l])},
                 {"bytes", file_bytes(g.lod_paths.levels[l])},
                 {"size", g.lods.levels[l].image_size}};
      if (l < g.lod_errors.size()) level["psnr_db"] = number_or_null(g.lod_errors[l].psnr);
      level["quantization"] = lod_quantization_json(g.lods.levels[l]);
      levels.push_back(std::move(level));
    }
    j["lods"] = std::move(levels);
    j["lods_file"] = file_name(g.lod_paths.combined);
  }
  if (g.cage) {
    Json c = to_json(*g.cage);
    c["file"] = file_name(g.cage->cage_path);
    c["displacement_file"] = file_name(g.cage->displacement_path);
    j["cage"] = std::move(c);
  }
  j["seconds"] = m.seconds;
  return j;
}

// Feature texels: the texel nearest each final location F_k, and per member the distance
// from the image's point there to the member's own feature vertex, relative to the largest
// distance from that texel to its 8 neighbours (the local sample spacing): consistent maps
// keep every ratio near or below 1.
Json feature_texels_json(const formats::CollectionManifest& manifest, const std::vector<formats::LoadedMember>& members,
                         const std::vector<ConvertedMember>& outputs, int n) {
  Json feats = Json::array();
  for (std::size_t f = 0; f < manifest.features.size(); ++f) {
    const auto [ti, tj] = nearest_texel(manifest.features[f].location, n);
    Json e;
    e["name"] = manifest.features[f].name;
    e["texel"] = {ti, tj};
    Json per = Json::array();
    for (std::size_t k = 0; k < outputs.size(); ++k) {
      const formats::LoadedMember& m = members[k];
      if (m.features.rows() != static_cast<Eigen::Index>(manifest.features.size())) {
        per.push_back(nullptr);
        continue;
      }
      const GeometryImage& image = outputs[k].assets.image;
      const Eigen::Vector3d p = image.position(ti, tj).cast<double>();
      double spacing = 0;
      for (int di = -1; di <= 1; ++di)
        for (int dj = -1; dj <= 1; ++dj) {
          const int i2 = ti + di, j2 = tj + dj;
          if (i2 < 0 || j2 < 0 || i2 >= n || j2 >= n) continue;
          spacing = std::max(spacing, (image.position(i2, j2).cast<double>() - p).norm());
        }
      const double d = (p - m.features.row(static_cast<Eigen::Index>(f)).transpose()).norm();
      per.push_back({{"member", m.name}, {"distance", d}, {"texel_spacing", spacing}});
    }
    e["members"] = std::move(per);
    feats.push_back(std::move(e));
  }
  return feats;
}

}  // namespace

Result<ConvertCollectionResult> convert_collection(const ConvertCollectionJob& job, const ProgressFn& progress,
                                                   const formats::KeepGoingFn& keep_going) {
  const ConvertOptions& o = job.options;
  SPHEREKIT_RETURN_IF_ERROR(check_convert_options(o));
  Stopwatch wall;
  SPHEREKIT_ASSIGN_OR_RETURN(formats::Collection info, formats::read_collection(job.collection));
  SPHEREKIT_RETURN_IF_ERROR(formats::require_staged_folder_target(job.output, kConvertReport));
  SPHEREKIT_ASSIGN_OR_RETURN(std::vector<formats::LoadedMember> members, formats::load_collection_members(info));
  // Every map must be a bijection before any work (as for one mesh).
  for (const formats::LoadedMember& m : members)
    if (const int flipped = count_flipped_faces(m.mesh.F, m.map.S); flipped != 0)
      return Status(ErrorCode::InvalidInput, job.collection + ": map of " + m.name + " has " + std::to_string(flipped) +
                                                 " flipped or degenerate faces on the sphere");

  // The levels' template (LodMode::Original): the collection's reference member, whose map
  // the others' were made consistent with (else the first member).
  int lod_template = 0;
  for (std::size_t k = 0; k < members.size(); ++k)
    if (info.manifest.reference && members[k].name == *info.manifest.reference) lod_template = static_cast<int>(k);

  ConvertCollectionResult result;
  result.job = job;
  Json& report = result.report;
  Status written = formats::write_staged_folder(
      job.output, kConvertReport,
      [&](const std::string& dir) -> Status {
        for (const formats::LoadedMember& m : members) {
          if (keep_going && !keep_going()) return Status(ErrorCode::Cancelled, "cancelled");
          Stopwatch t;
          ConvertedMember out;
          out.name = m.name;
          out.source = m.source;
          out.vertices = m.mesh.V.rows();
          out.faces = m.mesh.F.rows();
          GeometryOutputs names;
          names.image = (fs::path(dir) / (m.name + ".exr")).string();
          names.prefix = (fs::path(dir) / m.name).string();
          names.name = m.name;
          names.source_mesh = m.source;
          names.sphere_map = (fs::path(info.dir) / info.manifest.members[static_cast<std::size_t>(m.index)].map).string();
          names.lods_sphere_map = info.dir;
          SPHEREKIT_ASSIGN_OR_RETURN(out.assets,
                                     convert_geometry(m.mesh, m.map.S, o, names, /*collection_member=*/true, progress));
          out.seconds = t.seconds();
          result.members.push_back(std::move(out));
        }
        // One simplification of every member in R^3n, so level k has one connectivity in every
        // member and each level is also a morph-target glTF: Original simplifies the template
        // member's own mesh carried onto every member (template_lods.h), Adaptive the common
        // geometry-image remesh (adaptive_lods.h).
        if (o.lods > 0 && o.lod_mode != convert::LodMode::Uniform) {
          std::vector<GeometryImage> images;
          std::vector<convert::GltfLodOptions> lod_options;
          for (const ConvertedMember& c : result.members) {
            convert::GltfLodOptions lo;
            lo.mode = o.lod_mode;
            lo.levels = o.lods;
            lo.budget = o.budget;
            lo.reference_rms_error = c.assets.measured ? c.assets.error.rms : 0;
            lo.position_bits_rule = o.lod_position_bits;
            lo.normals = o.lod_normals;  // a viewer's flat normals do not change the connectivity
            lo.texcoords = o.lod_texcoords;  // welds the fold's copies alike on every member
            lo.lod0_max_vertices = c.vertices;  // the largest member's decides (gltf_lods.cpp)
            lo.name = c.name;
            lo.provenance = {c.source, info.dir};
            images.push_back(c.assets.image);
            lod_options.push_back(std::move(lo));
          }
          std::vector<convert::GltfLods> lods;
          result.lod_connectivity = o.lod_mode == convert::LodMode::Adaptive ? "remesh" : "template";
          if (o.lod_mode == convert::LodMode::Original) {
            SPHEREKIT_ASSIGN_OR_RETURN(lods, template_or_remesh_levels(members, lod_template, images, lod_options, o,
                                                                        progress, result));
          } else {
            SPHEREKIT_ASSIGN_OR_RETURN(lods, convert::build_consistent_gltf_lods(images, lod_options, progress));
          }
          RemeshErrorOptions psnr;
          psnr.samples = o.psnr_samples;
          psnr.threads = o.threads;
          for (std::size_t k = 0; k < result.members.size(); ++k) {
            GeometryAssets& a = result.members[k].assets;
            a.lods = std::move(lods[k]);
            SPHEREKIT_ASSIGN_OR_RETURN(a.lod_paths,
                                       convert::write_gltf_lods((fs::path(dir) / result.members[k].name).string(), a.lods));
            if (a.measured)
              for (const convert::GltfLodLevel& level : a.lods.levels)
                a.lod_errors.push_back(
                    remesh_error(members[k].mesh, TriMesh{level.primitive.decoded.mesh.V, level.primitive.decoded.mesh.F}, psnr));
          }
          for (int l = 0; result.members.size() >= 2 && l < o.lods; ++l) {
            std::vector<convert::GltfMesh> meshes;
            convert::GltfMorphOptions mo;
            for (const ConvertedMember& c : result.members) {
              meshes.push_back(c.assets.lods.levels[static_cast<std::size_t>(l)].mesh);
              mo.names.push_back(c.name);
            }
            mo.provenance = {job.collection, info.dir};
            SPHEREKIT_ASSIGN_OR_RETURN(auto morph, convert::build_gltf_morph_targets(meshes, mo));
            const std::string file = "collection_morph_lod" + std::to_string(l) + ".glb";
            SPHEREKIT_RETURN_IF_ERROR(formats::write_file_atomic((fs::path(dir) / file).string(), morph.glb));
            report["morph_lods"].push_back({{"file", file}, {"bytes", morph.glb.size()}, {"targets", morph.targets}});
          }
        }
        // One glTF with every member as a morph target of the first: possible only because
        // the consistent images share their texels, hence their vertices and faces.
        if (result.members.size() >= 2) {
          std::vector<convert::GltfMesh> meshes;
          convert::GltfMorphOptions mo;
          for (const ConvertedMember& c : result.members) {
            SPHEREKIT_ASSIGN_OR_RETURN(convert::GltfMesh g, convert::gltf_mesh_from_geometry_image(c.assets.image));
            meshes.push_back(std::move(g));
            mo.names.push_back(c.name);
          }
          mo.provenance = {job.collection, info.dir};
          SPHEREKIT_ASSIGN_OR_RETURN(auto morph, convert::build_gltf_morph_targets(meshes, mo));
          SPHEREKIT_RETURN_IF_ERROR(
              formats::write_file_atomic((fs::path(dir) / "collection_morph.glb").string(), morph.glb));
          report["morph"] = {{"file", "collection_morph.glb"}, {"bytes", morph.glb.size()}, {"targets", morph.targets}};
        }
        report["feature_texels"] = feature_texels_json(info.manifest, members, result.members, o.size);
        report["collection"] = fs::absolute(job.collection).lexically_normal().string();
        report["size"] = o.size;
        report["positions"] = texel_positions_name(o.positions);
        report["layout"] = "octahedral";
        Json list = Json::array();
        for (const ConvertedMember& c : result.members) list.push_back(member_json(c, o, dir));
        report["members"] = std::move(list);
        if (o.cage > 0)
          report["cage"] = {{"n", o.cage}, {"tile", o.cage_tile}, {"displacement", displacement_kind_name(o.displacement)}};
        report["lods"] = o.lods;
        if (o.lods > 0) {
          Json c = {{"kind", o.lod_mode == convert::LodMode::Uniform ? "uniform" : result.lod_connectivity}};
          if (!result.lod_template.empty()) c["template"] = result.lod_template, c["template_folds"] = result.lod_template_folds;
          if (!result.lod_connectivity_reason.empty()) c["reason"] = result.lod_connectivity_reason;
          if (!result.lod_choice.is_null()) c["choice"] = result.lod_choice;
          report["lod_connectivity"] = std::move(c);
        }
        report["version"] = kVersion;
        report["times"]["wall"] = wall.seconds();
        return formats::write_file_atomic((fs::path(dir) / kConvertReport).string(), report.dump(2) + "\n");
      },
      keep_going);
  SPHEREKIT_RETURN_IF_ERROR(written);
  result.wall_seconds = wall.seconds();
  return result;
}

}  // namespace spherekit::pipeline
