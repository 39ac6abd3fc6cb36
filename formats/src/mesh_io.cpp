// read_mesh / write_mesh: choose a format by extension, read or write the whole file at once.
#include "spherekit/formats/mesh_io.h"

#include <filesystem>

#include "mesh_codecs.h"
#include "spherekit/formats/atomic_file.h"
#include "spherekit/version.h"

namespace spherekit::formats {
namespace {

bool is_readable_extension(const std::string& ext) {
  return ext == "obj" || ext == "ply" || ext == "off" || ext == "stl" || ext == "gltf" || ext == "glb";
}

Status unsupported_extension(const std::string& path, const std::string& ext, const char* accepted) {
  const std::string what = ext.empty() ? "no file extension" : "unsupported mesh format '." + ext + "'";
  return Status(ErrorCode::Unsupported, path + ": " + what + " (" + accepted + ")");
}

constexpr const char* kReadable = "readable: .obj .ply .off .stl .gltf .glb";

}  // namespace

std::string file_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  if (!ext.empty()) ext.erase(0, 1);
  for (char& c : ext) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return ext;
}

namespace detail {

Result<TriMesh> parse_mesh(const std::string& path, std::string_view bytes, const ReadOptions& options,
                           ReadInfo* info) {
  const std::string ext = file_extension(path);
  if (!is_readable_extension(ext)) return unsupported_extension(path, ext, kReadable);
  if (bytes.empty()) return Status(ErrorCode::ParseError, path + ": file is empty");
  ReadInfo local;
  ReadInfo& out = info ? *info : local;
  out = ReadInfo{};
  if (ext == "obj") return read_obj(path, bytes, options, out);
  if (ext == "ply") return read_ply(path, bytes, options, out);
  if (ext == "off") return read_off(path, bytes, options, out);
  if (ext == "stl") return read_stl(path, bytes, options, out);
  return read_gltf(path, bytes, ext == "glb", options, out);
}

}  // namespace detail

Result<TriMesh> read_mesh(const std::string& path, const ReadOptions& options, ReadInfo* info) {
  // A folder given where meshes are expected (`spherekit run meshes/`) gets its own message,
  // not "no file extension".
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    return Status(ErrorCode::IoError, path + ": is a directory, not a mesh file (name the meshes in it, e.g. " +
                                          (std::filesystem::path(path) / "*.obj").string() + ")");
  // Check the extension first: no point reading a file we cannot parse.
  const std::string ext = file_extension(path);
  if (!is_readable_extension(ext)) return unsupported_extension(path, ext, kReadable);
  SPHEREKIT_ASSIGN_OR_RETURN(std::string bytes, read_file(path));
  return detail::parse_mesh(path, bytes, options, info);
}

Status write_mesh(const std::string& path, const TriMesh& mesh, const WriteOptions& options) {
  const std::string ext = file_extension(path);
  std::string bytes;
  if (ext == "obj") {
    bytes = detail::format_obj(mesh, options.precision, std::string("# written by spherekit ") + kVersion + "\n");
  } else if (ext == "ply") {
    bytes = detail::format_ply(mesh, options.binary, options.precision);
  } else {
    return unsupported_extension(path, ext, "writable: .obj .ply");
  }
  return write_file_atomic(path, bytes);
}

}  // namespace spherekit::formats
