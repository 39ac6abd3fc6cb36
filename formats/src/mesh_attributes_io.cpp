// read_mesh_with_attributes / write_mesh_with_attributes: the OBJ and PLY codecs with their
// attribute collection switched on; other formats read as read_mesh does, with no attributes.
#include <cmath>
#include <string>

#include "mesh_codecs.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/formats/mesh_attributes.h"
#include "spherekit/version.h"
#include "text_scan.h"

namespace spherekit::formats {

Result<AttributedMesh> read_mesh_with_attributes(const std::string& path, const ReadOptions& options,
                                                 ReadInfo* info) {
  const std::string ext = file_extension(path);
  if (ext != "obj" && ext != "ply") {
    SPHEREKIT_ASSIGN_OR_RETURN(TriMesh mesh, read_mesh(path, options, info));
    return AttributedMesh{std::move(mesh), {}};
  }
  SPHEREKIT_ASSIGN_OR_RETURN(std::string bytes, read_file(path));
  if (bytes.empty()) return Status(ErrorCode::ParseError, path + ": file is empty");
  ReadInfo local;
  ReadInfo& out = info ? *info : local;
  out = ReadInfo{};
  AttributedMesh result;
  auto mesh = ext == "obj" ? detail::read_obj(path, bytes, options, out, &result.attributes)
                           : detail::read_ply(path, bytes, options, out, &result.attributes);
  if (!mesh.ok()) return mesh.status();
  result.mesh = std::move(mesh).value();
  return result;
}

Status check_mesh_attributes(const TriMesh& mesh, const MeshAttributes& a) {
  const Eigen::Index nv = mesh.V.rows(), nf = mesh.F.rows();
  if (a.colors.rows() != 0 && a.colors.rows() != nv)
    return Status(ErrorCode::InvalidArgument, std::to_string(a.colors.rows()) + " colours for " + std::to_string(nv) +
                                                  " vertices");
  if (a.normals.rows() != 0 && a.normals.rows() != nv)
    return Status(ErrorCode::InvalidArgument, std::to_string(a.normals.rows()) + " normals for " +
                                                  std::to_string(nv) + " vertices");
  if (a.FT.rows() != 0 && a.FT.rows() != nf)
    return Status(ErrorCode::InvalidArgument, std::to_string(a.FT.rows()) + " texture faces for " +
                                                  std::to_string(nf) + " faces");
  if (a.FT.size() > 0 && (a.FT.minCoeff() < 0 || a.FT.maxCoeff() >= a.UV.rows()))
    return Status(ErrorCode::InvalidArgument, "texture index out of range (" + std::to_string(a.UV.rows()) +
                                                  " texture coordinates)");
  if (!a.colors.allFinite() || !a.normals.allFinite() || !a.UV.allFinite())
    return Status(ErrorCode::InvalidArgument, "non-finite attribute value");
  for (const std::string& name : a.material_libraries) {
    if (name.empty() || name.find_first_of(" \t\r\n") != std::string::npos)
      return Status(ErrorCode::InvalidArgument, "material library name '" + name + "' is empty or has white space");
  }
  if (a.material.find_first_of(" \t\r\n") != std::string::npos)
    return Status(ErrorCode::InvalidArgument, "material name '" + a.material + "' has white space");
  return Status();
}

Result<std::string> format_mesh_with_attributes(const std::string& path, const TriMesh& mesh,
                                                const MeshAttributes& attributes, const WriteOptions& options) {
  SPHEREKIT_RETURN_IF_ERROR(check_mesh_attributes(mesh, attributes).with_context(path));
  const std::string ext = file_extension(path);
  std::string bytes;
  if (ext == "obj") {
    bytes = detail::format_obj(mesh, options.precision, std::string("# written by spherekit ") + kVersion + "\n",
                               &attributes);
  } else if (ext == "ply") {
    if (attributes.FT.rows() > 0 || attributes.normals.rows() > 0)
      return Status(ErrorCode::InvalidArgument, path + ": PLY output keeps colours only (write .obj for texture "
                                                       "coordinates and normals)");
    bytes = detail::format_ply(mesh, options.binary, options.precision, &attributes);
  } else {
    return Status(ErrorCode::Unsupported, path + ": unsupported mesh format for attributes (writable: .obj .ply)");
  }
  return bytes;
}

Status write_mesh_with_attributes(const std::string& path, const TriMesh& mesh, const MeshAttributes& attributes,
                                  const WriteOptions& options) {
  SPHEREKIT_ASSIGN_OR_RETURN(std::string bytes, format_mesh_with_attributes(path, mesh, attributes, options));
  return write_file_atomic(path, bytes);
}

Result<std::vector<ObjMaterial>> read_mtl(const std::string& path) {
  SPHEREKIT_ASSIGN_OR_RETURN(std::string text, read_file(path));
  std::vector<ObjMaterial> out;
  detail::LineReader lines(text);
  std::string_view line, token;
  while (lines.next(line)) {
    std::string_view rest = detail::strip_comment(line);
    if (!detail::next_token(rest, token)) continue;
    const std::string statement(token);
    std::string last;
    while (detail::next_token(rest, token)) last = std::string(token);
    const std::string where = path + ":" + std::to_string(lines.number()) + ": ";
    if (statement == "newmtl") {
      if (last.empty()) return Status(ErrorCode::ParseError, where + "newmtl without a name");
      out.push_back(ObjMaterial{last, {}, {}});
      continue;
    }
    const bool diffuse = statement == "map_Kd";
    const bool normal = statement == "norm" || statement == "map_Bump" || statement == "bump";
    if (!diffuse && !normal) continue;
    if (out.empty()) return Status(ErrorCode::ParseError, where + statement + " before any newmtl");
    if (last.empty()) return Status(ErrorCode::ParseError, where + statement + " without a file");
    (diffuse ? out.back().diffuse_map : out.back().normal_map) = last;
  }
  return out;
}

std::string format_mtl(const std::vector<ObjMaterial>& materials) {
  std::string out = std::string("# written by spherekit ") + kVersion + "\n";
  for (const ObjMaterial& m : materials) {
    out += "newmtl " + m.name + "\nKa 0 0 0\nKd 1 1 1\nKs 0 0 0\nillum 1\n";
    if (!m.diffuse_map.empty()) out += "map_Kd " + m.diffuse_map + "\n";
    if (!m.normal_map.empty()) out += "norm " + m.normal_map + "\nmap_Bump -bm 1 " + m.normal_map + "\n";
  }
  return out;
}

}  // namespace spherekit::formats
