// transfer_attributes() (apps.h): colours, normals, texture coordinates or a texture of one
// collection member carried to another through the common sphere.
#include <filesystem>

#include "spherekit/convert/attribute_transfer.h"
#include "spherekit/convert/consistent_remesh.h"
#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/convert/png_image.h"
#include "spherekit/convert/similarity_fit.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/collection.h"
#include "spherekit/formats/mesh_attributes.h"
#include "spherekit/geometry_image.h"
#include "spherekit/pipeline/apps.h"
#include "spherekit/pipeline/paths.h"
#include "stopwatch.h"

namespace fs = std::filesystem;

namespace spherekit::pipeline {
namespace {

using formats::LoadedMember;
using formats::OutputFiles;

/// OUT without its extension: the stem of the sibling files (OUT.mtl, OUT_texture.png, ...).
std::string sibling_base(const std::string& output) { return (fs::path(output).parent_path() / fs::path(output).stem()).string(); }

/// The attribute source: --attributes, else A's mesh file; its vertices must be A's.
Result<formats::AttributedMesh> read_attribute_source(const TransferJob& a, const LoadedMember& A) {
  const std::string path = a.attributes.empty() ? A.source : a.attributes;
  SPHEREKIT_ASSIGN_OR_RETURN(formats::AttributedMesh m, formats::read_mesh_with_attributes(path));
  if (m.mesh.V.rows() != A.mesh.V.rows() || m.mesh.F.rows() != A.mesh.F.rows())
    return Status(ErrorCode::InvalidInput, path + ": has " + std::to_string(m.mesh.V.rows()) + " vertices and " +
                                               std::to_string(m.mesh.F.rows()) + " faces, member " + A.name + " " +
                                               std::to_string(A.mesh.V.rows()) + " and " +
                                               std::to_string(A.mesh.F.rows()));
  return m;
}

/// A's texture image: --texture, else the diffuse map of A's material (its OBJ's mtllib).
Result<std::string> find_texture(const TransferJob& a, const std::string& source, const formats::MeshAttributes& attr) {
  if (!a.texture.empty()) return a.texture;
  for (const std::string& lib : attr.material_libraries) {
    const fs::path mtl = fs::path(source).parent_path() / lib;
    std::error_code ec;
    if (!fs::is_regular_file(mtl, ec)) continue;
    SPHEREKIT_ASSIGN_OR_RETURN(std::vector<formats::ObjMaterial> materials, formats::read_mtl(mtl.string()));
    for (const formats::ObjMaterial& m : materials)
      if (!m.diffuse_map.empty() && (attr.material.empty() || m.name == attr.material))
        return (mtl.parent_path() / m.diffuse_map).string();
  }
  return Status(ErrorCode::InvalidInput, source + ": no texture image (no map_Kd in its material library; give --texture)");
}

}  // namespace

const char* transfer_what_name(TransferWhat what) {
  switch (what) {
    case TransferWhat::Colors: return "colors";
    case TransferWhat::Normals: return "normals";
    case TransferWhat::UV: return "uv";
    case TransferWhat::Texture: return "texture";
  }
  return "?";
}

Result<TransferResult> transfer_attributes(const TransferJob& a) {
  const std::string what = transfer_what_name(a.what);
  const std::string ext = formats::file_extension(a.output);
  if (a.what == TransferWhat::Colors ? (ext != "obj" && ext != "ply") : ext != "obj")
    return Status(ErrorCode::InvalidArgument, a.output + ": --what " + what + " writes " +
                                                              (a.what == TransferWhat::Colors ? ".obj or .ply" : ".obj") + " files");
  if (!is_geometry_image_size(a.size))
    return Status(ErrorCode::InvalidArgument, "--size " + std::to_string(a.size) + " is not 2^k+1 (65, 129, 257, ...)");
  SPHEREKIT_RETURN_IF_ERROR(require_output_folders({a.output}));
  Stopwatch clock;
  auto col = formats::read_collection(a.collection);
  if (!col.ok()) return col.status();
  auto A = formats::load_collection_member(col.value(), a.from);
  if (!A.ok()) return A.status();
  auto B = formats::load_collection_member(col.value(), a.to);
  if (!B.ok()) return B.status();
  auto src = read_attribute_source(a, A.value());
  if (!src.ok()) return src.status();
  const std::string src_path = a.attributes.empty() ? A->source : a.attributes;
  const formats::MeshAttributes& attr = src->attributes;

  Json rep;
  rep["command"] = "transfer";
  rep["collection"] = a.collection;
  rep["from"] = A->name;
  rep["to"] = B->name;
  rep["what"] = what;
  rep["attribute_source"] = src_path;
  OutputFiles out;
  formats::MeshAttributes written;
  TriMesh target = B->mesh;
  const std::string base = sibling_base(a.output);
  const std::string base_name = fs::path(base).filename().string();
  int in_holes = 0;

  if (a.what == TransferWhat::Colors) {
    if (attr.colors.rows() == 0)
      return Status(ErrorCode::InvalidInput, src_path + ": no vertex colours (PLY red/green/blue or OBJ 'v x y z r g b')");
    auto r = convert::transfer_vertex_attributes(A->mesh, A->map.S, RowMatXd(attr.colors), B->mesh, B->map.S);
    if (!r.ok()) return r.status();
    written.colors = r->values;
    in_holes = r->vertices_in_holes;
  } else if (a.what == TransferWhat::UV || a.what == TransferWhat::Texture) {
    if (attr.FT.rows() == 0)
      return Status(ErrorCode::InvalidInput, src_path + ": no texture coordinates on every face corner");
    std::string image;
    if (a.what == TransferWhat::Texture) {
      auto t = find_texture(a, src_path, attr);
      if (!t.ok()) return t.status();
      image = t.value();
    }
    auto r = convert::transfer_texture_coordinates(A->mesh, A->map.S, attr.UV, attr.FT, B->mesh, B->map.S);
    if (!r.ok()) return r.status();
    written.UV = r->UV;
    written.FT = r->FT;
    in_holes = r->vertices_in_holes;
    rep["charts"] = r->charts;
    rep["seam_faces"] = r->seam_faces;
    if (a.what == TransferWhat::Texture) {
      auto bytes = formats::read_file(image);
      if (!bytes.ok()) return bytes.status();
      const std::string copy = base_name + "_texture" + fs::path(image).extension().string();
      written.material_libraries = {base_name + ".mtl"};
      written.material = "transferred";
      out.add(base + ".mtl", formats::format_mtl({{"transferred", copy, {}}}));
      out.add(base + "_texture" + fs::path(image).extension().string(), std::move(bytes).value());
      rep["texture"] = image;
    }
  } else {  // normals: A's normal map on B's consistent remesh
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    if (a.align && A->features.rows() >= 3 && A->features.rows() == B->features.rows()) {
      auto sim = convert::fit_similarity(A->features, B->features, true);
      if (sim.ok()) R = sim->R;
    }
    rep["rotation"] = {{R(0, 0), R(0, 1), R(0, 2)}, {R(1, 0), R(1, 1), R(1, 2)}, {R(2, 0), R(2, 1), R(2, 2)}};
    auto ra = convert::consistent_remesh(A->mesh, A->map.S, a.size, GeometryImageOptions{.threads = a.threads});
    if (!ra.ok()) return ra.status().with_context(A->name);
    auto rb = convert::consistent_remesh(B->mesh, B->map.S, a.size, GeometryImageOptions{.threads = a.threads});
    if (!rb.ok()) return rb.status().with_context(B->name);
    auto map = convert::bake_normal_map(ra->image, R);
    if (!map.ok()) return map.status();
    auto png = convert::encode_png(map.value());
    if (!png.ok()) return png.status();
    auto points = convert::gltf_mesh_from_geometry_image(rb->image);
    if (!points.ok()) return points.status();
    target = rb->mesh;
    const auto N = static_cast<Eigen::Index>(a.size);
    written.UV.resize(N * N, 2);
    written.normals.resize(target.V.rows(), 3);
    for (Eigen::Index p = 0; p < N * N; ++p) {
      // glTF's (s, t) has t from the image's top; OBJ's v runs from its bottom.
      written.UV.row(p) << points->UV(p, 0), 1.0 - points->UV(p, 1);
      const Eigen::Vector3d n = (R * ra->image.normal(static_cast<int>(p / N), static_cast<int>(p % N)).cast<double>()).normalized();
      written.normals.row(points->position_index[static_cast<std::size_t>(p)]) = n.transpose();
    }
    written.FT = points->F;
    written.material_libraries = {base_name + ".mtl"};
    written.material = "transferred_normals";
    out.add(base + ".mtl", formats::format_mtl({{"transferred_normals", {}, base_name + "_normals.png"}}));
    out.add(base + "_normals.png", std::move(png).value());
    rep["size"] = a.size;
    rep["normal_space"] = "object";
    rep["remesh_vertices"] = target.V.rows();
  }

  // The sibling files first, the mesh that refers to them last; if the mesh cannot be
  // written the siblings are removed again, so the outputs appear together or not at all.
  Status check = formats::check_mesh_attributes(target, written);
  if (!check.ok()) return Status(ErrorCode::Internal, check.message());
  rep["vertices_in_holes"] = in_holes;
  rep["outputs"] = Json::array();
  rep["outputs"].push_back(a.output);
  for (const auto& f : out.files()) rep["outputs"].push_back(f.first);
  rep["seconds"] = clock.seconds();
  if (Status s = out.write_all(); !s.ok()) return s;
  if (Status s = formats::write_mesh_with_attributes(a.output, target, written); !s.ok()) {
    std::error_code ec;
    for (const auto& f : out.files()) fs::remove(f.first, ec);
    return s;
  }
  TransferResult result;
  result.from = A->name;
  result.to = B->name;
  result.vertices = target.V.rows();
  result.vertices_in_holes = in_holes;
  result.report = std::move(rep);
  return result;
}

}  // namespace spherekit::pipeline
