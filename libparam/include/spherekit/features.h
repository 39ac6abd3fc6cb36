// Feature (landmark) vertices and target points on the sphere.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace spherekit {

/// A named feature vertex of one mesh (file format: `name vertex_index`, 0-based).
struct Landmark {
  std::string name;
  int vertex = -1;
};

/// A named point on the unit sphere (file format: `name x y z`).
struct SpherePoint {
  std::string name;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

}  // namespace spherekit
