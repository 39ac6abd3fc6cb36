#include "spherekit/remove_faces.h"

#include <numeric>

#include "spherekit/check_mesh.h"

namespace spherekit {

TriMesh remove_faces(const TriMesh& mesh, const std::vector<std::uint8_t>& drop, std::vector<int>* new_index) {
  const Eigen::Index nv = mesh.V.rows();
  std::vector<int> index(static_cast<std::size_t>(nv), -1);
  bool valid = drop.size() == static_cast<std::size_t>(mesh.F.rows());
  for (Eigen::Index f = 0; valid && f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) valid = valid && mesh.F(f, k) >= 0 && mesh.F(f, k) < nv;
  if (!valid) {
    std::iota(index.begin(), index.end(), 0);
    if (new_index) *new_index = std::move(index);
    return mesh;
  }
  Eigen::Index faces = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    if (!drop[static_cast<std::size_t>(f)]) {
      ++faces;
      for (int k = 0; k < 3; ++k) index[static_cast<std::size_t>(mesh.F(f, k))] = 0;
    }
  int vertices = 0;
  for (int& i : index)
    if (i == 0) i = vertices++;
  TriMesh out;
  out.V.resize(vertices, 3);
  for (Eigen::Index v = 0; v < nv; ++v)
    if (const int i = index[static_cast<std::size_t>(v)]; i >= 0) out.V.row(i) = mesh.V.row(v);
  out.F.resize(faces, 3);
  Eigen::Index row = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    if (drop[static_cast<std::size_t>(f)]) continue;
    for (int k = 0; k < 3; ++k) out.F(row, k) = index[static_cast<std::size_t>(mesh.F(f, k))];
    ++row;
  }
  if (new_index) *new_index = std::move(index);
  return out;
}

int remove_unreferenced_vertices(TriMesh& mesh, std::vector<int>* old_to_new) {
  std::vector<int> index;
  TriMesh kept = remove_faces(mesh, std::vector<std::uint8_t>(static_cast<std::size_t>(mesh.F.rows()), 0), &index);
  const int dropped = static_cast<int>(mesh.V.rows() - kept.V.rows());
  mesh = std::move(kept);
  if (old_to_new) *old_to_new = std::move(index);
  return dropped;
}

}  // namespace spherekit
