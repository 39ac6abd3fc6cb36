// libFuzzer harness: OBJ and PLY with their attributes (per-vertex colours, OBJ texture
// coordinates and face texture indices, mtllib/usemtl), as read_mesh_with_attributes reads them.
// The first byte picks the format (even: OBJ, odd: PLY), the rest is the file. Contract: a
// successful read gives attributes consistent with the mesh (check_mesh_attributes), and the
// writer's bytes for them read back with the same counts.
#include "fuzz_common.h"
#include "spherekit/formats/mesh_attributes.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace spherekit;
  if (size == 0) return 0;
  const std::string path = data[0] % 2 == 0 ? "fuzz.obj" : "fuzz.ply";
  const std::string_view bytes = fuzz::bytes_of(data + 1, size - 1);
  formats::ReadInfo info;
  formats::MeshAttributes attributes;
  Result<TriMesh> mesh = path.back() == 'j' ? formats::detail::read_obj(path, bytes, {}, info, &attributes)
                                            : formats::detail::read_ply(path, bytes, {}, info, &attributes);
  if (!mesh.ok()) {
    fuzz::require_good_error(mesh.status(), path);
    return 0;
  }
  fuzz::require(formats::check_mesh_attributes(mesh.value(), attributes).ok());
  Result<std::string> text = formats::format_mesh_with_attributes(path, mesh.value(), attributes);
  fuzz::require(text.ok());
  formats::ReadInfo info2;
  formats::MeshAttributes back;
  Result<TriMesh> again = path.back() == 'j' ? formats::detail::read_obj(path, text.value(), {}, info2, &back)
                                             : formats::detail::read_ply(path, text.value(), {}, info2, &back);
  fuzz::require(again.ok());
  fuzz::require(again->V.rows() == mesh->V.rows() && again->F.rows() == mesh->F.rows());
  fuzz::require(back.colors.rows() == attributes.colors.rows() && back.UV.rows() == attributes.UV.rows());
  return 0;
}
