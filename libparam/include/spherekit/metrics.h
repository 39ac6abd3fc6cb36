// Measures of a sphere map: the same quantities and definitions as the independent
// evaluator shared/tools/evalsphere.py (Sander et al. 2001 stretch, Praun & Hoppe 2003).
#pragma once

#include <optional>
#include <vector>

#include "spherekit/features.h"
#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit {

/// A feature vertex and where it must land on the sphere.
struct FeatureTarget {
  int vertex = -1;
  Eigen::Vector3d target = Eigen::Vector3d::UnitZ();
};

struct SphereMapMetrics {
  int vertices = 0, faces = 0;
  double radius_dev = 0;      ///< max | |s| - 1 |
  int flipped = 0;            ///< faces with det[a,b,c] < 0 by exact predicate (relative to winding +1)
  int flipped_majority = 0;   ///< evalsphere's count: faces disagreeing with the majority orientation
  int degenerate = 0;         ///< faces with det[a,b,c] == 0 exactly
  int degenerate_tol = 0;     ///< evalsphere's count: |det| <= 1e-15
  bool closed = false;
  double winding = 0;         ///< closed only: signed spherical area / 4 pi
  double fold_excess = 0;     ///< closed only: (sum |area| - 4 pi) / 4 pi
  double efficiency = 0;      ///< 1 / L2n^2, chord-triangle Jacobians, surface-area weights
  double l2_stretch = 0;      ///< normalised L2 stretch L2n (efficiency = 1/L2n^2)
  double linf = 0;            ///< normalised max singular value
  double conformal_mean = 0;  ///< area-weighted mean of Gamma/gamma
  double conformal_p95 = 0;   ///< area-weighted 95th percentile of Gamma/gamma
  double area_log_mean = 0;   ///< area-weighted mean |log normalised area ratio|
  std::optional<double> feature_err_deg;  ///< max angle feature vertex -> target (degrees)
};

/// Evaluates sphere map S (#V by 3; normalised here, deviation reported) of `mesh`.
/// `face_mask` (optional, #F entries): only faces with a nonzero entry count in the
/// stretch statistics (e.g. the real faces of a hole-filled mesh); orientation counts
/// use all faces. Errors: InvalidInput if sizes disagree or S is not finite.
Result<SphereMapMetrics> evaluate_sphere_map(const TriMesh& mesh, const RowMat3d& S,
                                             const std::vector<FeatureTarget>& targets = {},
                                             const std::vector<char>* face_mask = nullptr);

/// Number of faces with det[S(a), S(b), S(c)] <= 0 by the exact predicate (0 for a valid map).
int count_flipped_faces(const RowMat3i& F, const RowMat3d& S);

// Details of evaluate_sphere_map (definitions are evalsphere.py's, operation for operation):
// - Exact counts (`flipped`, `degenerate`, count_flipped_faces) apply orient3d_origin to the
//   rows of S as given: scaling a row by a positive factor never changes the exact sign,
//   while normalising first would round. count_flipped_faces = flipped + degenerate; it also
//   counts faces with an out-of-range index or a non-finite point (it cannot report errors).
// - `flipped_majority`, `degenerate_tol`, `winding`, `fold_excess` use the normalised points in
//   double, like evalsphere. winding/fold_excess stay 0 when the mesh is not closed (every
//   undirected edge in exactly two faces).
// - With `face_mask`, the stretch statistics (efficiency, l2_stretch, linf, conformal_*,
//   area_log_mean) are those evalsphere reports for the mesh made of the masked faces only,
//   while orientation counts, closedness and winding use all faces; radius_dev covers all
//   vertices.
// - feature_err_deg uses atan2(|s x t|, s . t) rather than evalsphere's arccos(s . t): the
//   same angle, but accurate near 0 where arccos has ~1e-8 rad of rounding noise.
// - More InvalidInput cases: no faces, a face index out of range, non-finite mesh vertices, a
//   zero sphere point, a mask selecting no face, a target vertex out of range or a zero/non-
//   finite target. Cost: O(#V + #F); about 35 ms of CPU for 330k faces (one core, no threads).

/// Stretch terms of one face (Sander et al. 2001) as evalsphere.py's stretch_terms(): the affine
/// map from the domain (chord) triangle q0 q1 q2 to the surface triangle p0 p1 p2, with the
/// domain in the orthonormal frame s = (q1-q0)/|q1-q0|, t in its plane orthogonal to s.
struct FaceStretch {
  double a = 0;             ///< Ss . Ss (squared stretch along s)
  double b = 0;             ///< Ss . St
  double c = 0;             ///< St . St (squared stretch along t)
  double area_domain = 0;   ///< area of the domain (chord) triangle
  double area_surface = 0;  ///< area of the surface triangle
};

/// Stretch terms of one face; singular values of the Jacobian are
/// sqrt((a + c +- sqrt((a - c)^2 + 4 b^2)) / 2). A degenerate domain gives huge, finite terms
/// (lengths are clamped at 1e-300 like evalsphere), not an error.
FaceStretch face_stretch(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                         const Eigen::Vector3d& q0, const Eigen::Vector3d& q1, const Eigen::Vector3d& q2);

}  // namespace spherekit
