// `spherekit transfer`: per-vertex colours, normals (as a normal map), texture coordinates or a
// texture image from one member of a collection to another through the common sphere
// (Asirvatham, Praun, Hoppe 2005, Fig. 6). The algorithms are in
// convert/attribute_transfer.h; this file reads, calls and writes.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "cli_common.h"
#include "commands.h"
#include "member_io.h"
#include "spherekit/convert/attribute_transfer.h"
#include "spherekit/convert/consistent_remesh.h"
#include "spherekit/convert/gltf_mesh.h"
#include "spherekit/convert/similarity_fit.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/mesh_attributes.h"
#include "spherekit/geometry_image.h"

namespace fs = std::filesystem;

namespace spherekit::cli {
namespace {

struct TransferArgs {
  std::string dir, from, to, what, output;
  std::string attributes;  // attribute source file (default: A's mesh file)
  std::string texture;     // texture image (default: from A's material library)
  int size = 129;
  bool no_align = false;
  std::string report;
  bool quiet = false;
};

/// OUT without its extension: the stem of the sibling files (OUT.mtl, OUT_texture.png, ...).
std::string sibling_base(const std::string& output) { return (fs::path(output).parent_path() / fs::path(output).stem()).string(); }

/// The attribute source: --attributes, else A's mesh file; its vertices must be A's.
Result<formats::AttributedMesh> read_attribute_source(const TransferArgs& a, const Member& A) {
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
Result<std::string> find_texture(const TransferArgs& a, const std::string& source, const formats::MeshAttributes& attr) {
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

int run_transfer(const TransferArgs& a) {
  const std::string ext = formats::file_extension(a.output);
  if (a.what == "colors" ? (ext != "obj" && ext != "ply") : ext != "obj")
    return print_error(Status(ErrorCode::InvalidArgument, a.output + ": --what " + a.what + " writes " +
                                                              (a.what == "colors" ? ".obj or .ply" : ".obj") + " files"));
  if (!is_geometry_image_size(a.size))
    return print_error(Status(ErrorCode::InvalidArgument, "--size " + std::to_string(a.size) + " is not 2^k+1 (65, 129, 257, ...)"));
  if (Status s = require_output_folders({a.output, a.report}); !s.ok()) return print_error(s);
  Stopwatch clock;
  auto col = read_collection(a.dir);
  if (!col.ok()) return print_error(col.status());
  auto A = load_member(col.value(), a.from);
  if (!A.ok()) return print_error(A.status());
  auto B = load_member(col.value(), a.to);
  if (!B.ok()) return print_error(B.status());
  auto src = read_attribute_source(a, A.value());
  if (!src.ok()) return print_error(src.status());
  const std::string src_path = a.attributes.empty() ? A->source : a.attributes;
  const formats::MeshAttributes& attr = src->attributes;

  Json rep;
  rep["command"] = "transfer";
  rep["collection"] = a.dir;
  rep["from"] = A->name;
  rep["to"] = B->name;
  rep["what"] = a.what;
  rep["attribute_source"] = src_path;
  OutputFiles out;
  formats::MeshAttributes written;
  TriMesh target = B->mesh;
  const std::string base = sibling_base(a.output);
  const std::string base_name = fs::path(base).filename().string();
  int in_holes = 0;

  if (a.what == "colors") {
    if (attr.colors.rows() == 0)
      return print_error(Status(ErrorCode::InvalidInput, src_path + ": no vertex colours (PLY red/green/blue or OBJ 'v x y z r g b')"));
    auto r = convert::transfer_vertex_attributes(A->mesh, A->map.S, RowMatXd(attr.colors), B->mesh, B->map.S);
    if (!r.ok()) return print_error(r.status());
    written.colors = r->values;
    in_holes = r->vertices_in_holes;
  } else if (a.what == "uv" || a.what == "texture") {
    if (attr.FT.rows() == 0)
      return print_error(Status(ErrorCode::InvalidInput, src_path + ": no texture coordinates on every face corner"));
    std::string image;
    if (a.what == "texture") {
      auto t = find_texture(a, src_path, attr);
      if (!t.ok()) return print_error(t.status());
      image = t.value();
    }
    auto r = convert::transfer_texture_coordinates(A->mesh, A->map.S, attr.UV, attr.FT, B->mesh, B->map.S);
    if (!r.ok()) return print_error(r.status());
    written.UV = r->UV;
    written.FT = r->FT;
    in_holes = r->vertices_in_holes;
    rep["charts"] = r->charts;
    rep["seam_faces"] = r->seam_faces;
    if (a.what == "texture") {
      auto bytes = formats::read_file(image);
      if (!bytes.ok()) return print_error(bytes.status());
      const std::string copy = base_name + "_texture" + fs::path(image).extension().string();
      written.material_libraries = {base_name + ".mtl"};
      written.material = "transferred";
      out.add(base + ".mtl", formats::format_mtl({{"transferred", copy, {}}}));
      out.add(base + "_texture" + fs::path(image).extension().string(), std::move(bytes).value());
      rep["texture"] = image;
    }
  } else {  // normals: A's normal map on B's consistent remesh
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    if (!a.no_align && A->features.rows() >= 3 && A->features.rows() == B->features.rows()) {
      auto sim = convert::fit_similarity(A->features, B->features, true);
      if (sim.ok()) R = sim->R;
    }
    rep["rotation"] = {{R(0, 0), R(0, 1), R(0, 2)}, {R(1, 0), R(1, 1), R(1, 2)}, {R(2, 0), R(2, 1), R(2, 2)}};
    auto ra = convert::consistent_remesh(A->mesh, A->map.S, a.size);
    if (!ra.ok()) return print_error(ra.status().with_context(A->name));
    auto rb = convert::consistent_remesh(B->mesh, B->map.S, a.size);
    if (!rb.ok()) return print_error(rb.status().with_context(B->name));
    auto map = convert::bake_normal_map(ra->image, R);
    if (!map.ok()) return print_error(map.status());
    auto png = convert::encode_png(map.value());
    if (!png.ok()) return print_error(png.status());
    auto points = convert::gltf_mesh_from_geometry_image(rb->image);
    if (!points.ok()) return print_error(points.status());
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
  if (!check.ok()) return print_error(Status(ErrorCode::Internal, check.message()));
  rep["vertices_in_holes"] = in_holes;
  rep["outputs"] = Json::array();
  rep["outputs"].push_back(a.output);
  for (const auto& f : out.files()) rep["outputs"].push_back(f.first);
  rep["seconds"] = clock.seconds();
  if (Status s = out.write_all(); !s.ok()) return print_error(s);
  if (Status s = formats::write_mesh_with_attributes(a.output, target, written); !s.ok()) {
    std::error_code ec;
    for (const auto& f : out.files()) fs::remove(f.first, ec);
    return print_error(s);
  }
  if (!a.report.empty()) {
    if (Status s = write_json_atomic(a.report, rep); !s.ok()) return print_error(s);
  }
  if (!a.quiet) {
    std::printf("transfer %s: %s -> %s: %s (%lld vertices", a.what.c_str(), A->name.c_str(), B->name.c_str(),
                a.output.c_str(), static_cast<long long>(target.V.rows()));
    if (in_holes) std::printf(", %d in holes of %s", in_holes, A->name.c_str());
    std::printf(")\n");
  }
  return 0;
}

}  // namespace

int run_transfer_job(const std::string& dir, const std::string& from, const std::string& to, const std::string& what,
                     const std::string& output, const std::string& attributes, const std::string& report, bool quiet) {
  TransferArgs a;
  a.dir = dir;
  a.from = from;
  a.to = to;
  a.what = what;
  a.output = output;
  a.attributes = attributes;
  a.report = report;
  a.quiet = quiet;
  return run_transfer(a);
}

void register_transfer(CLI::App& app) {
  auto args = std::make_shared<TransferArgs>();
  CLI::App* cmd = add_command(
      app, "transfer", "Transfer colours, normals, texture coordinates or a texture between collection members",
      "A and B are members of the collection DIR ('spherekit consistent'), by name or mesh file.\n"
      "Every vertex of B is located on the common sphere in A's map and A's attribute is\n"
      "interpolated there (paper Fig. 6):\n"
      "  colors   A's vertex colours (PLY red/green/blue, OBJ 'v x y z r g b') -> OUT (.ply/.obj)\n"
      "  uv       A's texture coordinates (per face corner, charts kept apart at seams) -> OUT.obj\n"
      "  texture  the same plus OUT.mtl and OUT_texture.EXT, a copy of A's image (--texture, else\n"
      "           map_Kd of A's material library), so B shows A's texture\n"
      "  normals  A's normals as an object-space normal map in the geometry-image domain the\n"
      "           members share (OUT_normals.png, --size texels), on B's consistent remesh\n"
      "           (OUT.obj with texel-centre texture coordinates and the normals as 'vn', OUT.mtl);\n"
      "           rotated by the rotation aligning A's features with B's unless --no-align\n"
      "The attributes are read from A's mesh file, or from --attributes (same vertices as A).\n"
      "Outputs are written together or not at all; --report writes the numbers as JSON.",
      "  spherekit transfer heads --from alice --to bob --what colors -o bob_colored.ply\n"
      "  spherekit transfer heads --from alice --to bob --what texture -o bob_textured.obj\n"
      "  spherekit transfer heads --from alice --to bob --what normals -o bob_normals.obj --size 257");
  cmd->add_option("DIR", args->dir, "collection folder")->required();
  cmd->add_option("--from", args->from, "source member A (name or mesh file)")->required();
  cmd->add_option("--to", args->to, "target member B (name or mesh file)")->required();
  cmd->add_option("--what", args->what, "colors, normals, uv or texture")
      ->required()
      ->check(CLI::IsMember({"colors", "normals", "uv", "texture"}));
  cmd->add_option("-o,--output", args->output, "output mesh (.obj; .ply also for colors)")->required();
  cmd->add_option("--attributes", args->attributes, "read A's attributes from this file (A's vertices and faces)");
  cmd->add_option("--texture", args->texture, "A's texture image (texture; default: from A's .mtl)");
  cmd->add_option("--size", args->size, "normals: normal map and remesh size, 2^k+1")->capture_default_str();
  cmd->add_flag("--no-align", args->no_align, "normals: do not rotate A's normals into B's orientation");
  cmd->add_option("--report", args->report, "write a JSON report here");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing but errors");
  cmd->callback([args] { set_exit_code(run_transfer(*args)); });
}

}  // namespace spherekit::cli
