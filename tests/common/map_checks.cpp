#include "map_checks.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "spherekit/metrics.h"

namespace spherekit::test {

void require_valid_map(const TriMesh& mesh, const RowMat3d& S) {
  REQUIRE(S.rows() == mesh.V.rows());
  for (Eigen::Index i = 0; i < S.rows(); ++i) REQUIRE(std::abs(S.row(i).norm() - 1.0) < 1e-12);
  REQUIRE(count_flipped_faces(mesh.F, S) == 0);
  auto m = evaluate_sphere_map(mesh, S);
  REQUIRE(m.ok());
  if (m->closed) REQUIRE(std::abs(m->winding - 1.0) < 1e-9);
}

}  // namespace spherekit::test
