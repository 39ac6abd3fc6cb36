// The mesh type at every API boundary: plain row-major V/F arrays, no hidden state.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

namespace spherekit {

using RowMat3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using RowMat3i = Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;
using RowMatXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Triangle mesh as plain arrays; no behaviour, no hidden caches.
struct TriMesh {
  RowMat3d V;  ///< #V by 3 vertex positions
  RowMat3i F;  ///< #F by 3 vertex indices into V, counter-clockwise seen from outside
};

}  // namespace spherekit
