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
        // Adaptive levels: one simplification of every member in R^3n (adaptive_lods.h), so level
        // k has one connectivity in every member and each level is also a morph-target glTF.
        if (o.lods > 0 && o.lod_mode != convert::LodMode::Uniform) {  // Original: adaptive for members
          std::vector<GeometryImage> images;
          std::vector<convert::GltfLodOptions> lod_options;
          for (const ConvertedMember& c : result.members) {
            convert::GltfLodOptions lo;
            lo.mode = convert::LodMode::Adaptive;
            lo.levels = o.lods;
            lo.budget = o.budget;
            lo.reference_rms_error = c.assets.measured ? c.assets.error.rms : 0;
            lo.position_bits_rule = o.lod_position_bits;
            lo.normals = o.lod_normals;  // a viewer's flat normals do not change the connectivity
            lo.lod0_max_vertices = c.vertices;  // the largest member's decides (gltf_lods.cpp)
            lo.name = c.name;
            lo.provenance = {c.source, info.dir};
            images.push_back(c.assets.image);
            lod_options.push_back(std::move(lo));
          }
          SPHEREKIT_ASSIGN_OR_RETURN(std::vector<convert::GltfLods> lods,
                                     convert::build_consistent_gltf_lods(images, lod_options, progress));
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
