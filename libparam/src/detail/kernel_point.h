// A point inside the kernel of a vertex's ring on the sphere (shared by the constrained
// stage's untangling and the correspondence refinement's hole fans).
#pragma once

#include <array>
#include <vector>

#include "spherekit/mesh.h"

namespace spherekit::detail {

// Spherical Chebyshev centre of v's kernel (maximize min over ring faces of n_f . x, with
// n_f = S_a x S_b / |S_a x S_b| for ring face (v, a, b)) by projected subgradient ascent; true
// if the point found makes every ring face positive by the exact predicate. When the kernel
// is empty and `compromise` is given, it receives the best max-min point found (some ring
// faces stay negative there, by as little as possible). `work`, if given, counts the
// subgradient steps taken (the callers' budget).
bool kernel_point(const RowMat3d& S, const std::vector<std::array<int, 2>>& ring, const Eigen::Vector3d& start,
                  Eigen::Vector3d* out, Eigen::Vector3d* compromise = nullptr, long* work = nullptr);

}  // namespace spherekit::detail
