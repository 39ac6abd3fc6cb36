// Dense correspondence through consistent sphere maps (Asirvatham, Praun, Hoppe 2005 §1:
// "the parameterizations ... provide a correspondence between all the meshes"): a surface
// point of mesh A goes to its sphere point through A's map, then to the surface point of B
// with the same sphere point. Plus the standard measure of such a map's quality.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit {

/// A point on a triangle mesh: a face and barycentrics (>= 0, sum 1) in it.
struct SurfacePoint {
  int face = -1;
  Eigen::Vector3d bary{1.0 / 3, 1.0 / 3, 1.0 / 3};
};

/// The 3-D position of a surface point.
Eigen::Vector3d surface_position(const TriMesh& mesh, const SurfacePoint& p);

/// The surface point of `mesh` at vertex v (the first face around it, that corner's weight 1).
/// Returns face -1 for an isolated vertex.
SurfacePoint vertex_surface_point(const TriMesh& mesh, int v);

/// Closest points on a triangle mesh (uniform grid over the bounding box, exact point-triangle
/// distance; visits cells in growing shells until no nearer face can exist).
class ClosestPointLocator {
 public:
  explicit ClosestPointLocator(const TriMesh& mesh);
  ~ClosestPointLocator();
  ClosestPointLocator(ClosestPointLocator&&) noexcept;
  ClosestPointLocator& operator=(ClosestPointLocator&&) noexcept;
  /// The surface point nearest to q (face -1 only for a mesh without faces). Thread-safe.
  SurfacePoint closest(const Eigen::Vector3d& q) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One transferred point.
struct TransferredPoint {
  SurfacePoint point;   ///< on the target mesh
  bool in_hole = false; ///< the sphere point fell in a hole of the target (nearest point given)
};

/// Maps surface points of `from` (with sphere map S_from, #V by 3) to `to` (map S_to): each
/// point's sphere point is the central projection of its chord-triangle point (the inverse of
/// the gnomonic barycentrics used to locate), located in `to`'s map.
/// Errors: InvalidInput (map sizes differ from the meshes, a point's face out of range).
Result<std::vector<TransferredPoint>> transfer_points(const TriMesh& from, const RowMat3d& S_from,
                                                      const std::vector<SurfacePoint>& points, const TriMesh& to,
                                                      const RowMat3d& S_to);

/// Error statistics of a correspondence (Princeton protocol, Kim et al. 2011): for each pair,
/// the geodesic distance on the target from the predicted point to the true vertex, divided
/// by sqrt(target area). Geodesics are edge-graph Dijkstra distances from the true vertex
/// plus the straight step from a corner of the predicted point's face (as
/// shared/tools/evalcorr.py, so the numbers compare).
struct CorrespondenceError {
  int pairs = 0;
  double mean = 0, median = 0, p90 = 0, max = 0;
  double under_0025 = 0, under_005 = 0, under_01 = 0;  ///< fractions of pairs below 0.025, 0.05, 0.1
};

/// `predicted[i]` is where the map sends pair i; `truth[i]` is the true vertex of `to`.
/// Errors: InvalidInput (sizes, indices out of range), InvalidArgument (no pairs).
Result<CorrespondenceError> correspondence_error(const TriMesh& to, const std::vector<SurfacePoint>& predicted,
                                                 const std::vector<int>& truth);

}  // namespace spherekit
