// libFuzzer harness: sphere-map OBJ files (read_sphere_map: points plus the provenance
// header). The first byte picks the mesh's vertex count (0..15); the rest is the file. The
// mesh has no faces, so the reader's face comparison (a map of another mesh) is skipped here;
// the formats tests cover it.
#include <cmath>

#include "fuzz_common.h"
#include "mesh_codecs.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace spherekit;
  if (size == 0) return 0;
  TriMesh mesh;
  mesh.V = RowMat3d::Zero(data[0] % 16, 3);
  const std::string path = "fuzz.sphere.obj";
  auto read = formats::detail::parse_sphere_map(path, fuzz::bytes_of(data + 1, size - 1), mesh);
  if (!read.ok()) {
    fuzz::require_good_error(read.status(), path);
    return 0;
  }
  // Contract: one finite unit vector per mesh vertex.
  const RowMat3d& S = read->S;
  fuzz::require(S.rows() == mesh.V.rows());
  for (Eigen::Index i = 0; i < S.rows(); ++i) {
    fuzz::require(S.row(i).allFinite());
    fuzz::require(std::abs(S.row(i).norm() - 1) < 1e-12);
  }
  return 0;
}
