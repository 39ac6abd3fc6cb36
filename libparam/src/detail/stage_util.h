// Small pieces every parameterization stage shares: timing, the provenance digest of its
// shape-defining options, and the normalization of the input. Internal to libparam.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>

#include "detail/sphere_state.h"
#include "spherekit/mesh.h"
#include "spherekit/sphere_param.h"

namespace spherekit::detail {

/// The optimizer settings of a stage: the effort preset plus the options' regularizer,
/// seed and threads.
inline OptimizerSettings optimizer_settings(const SphereParamOptions& o) {
  OptimizerSettings s = settings_for_effort(o.effort);
  s.regularizer_weight = o.regularizer_weight;
  if (o.precise_layout && s.movetol_rel > 0) {  // SphereParamOptions::precise_layout (effort 2)
    s.precise_vertices = 3000;
    s.precise_movetol_rel = s.movetol_rel / 4;
    s.precise_rounds = 10;
    s.final_iter = std::max(s.final_iter, 3);
    s.fine_split_distance = 0.95;
    s.fine_split_vertices = kCoarseLevelVertices;
    s.area_floor_rel = 0.03;
    s.pass_work_cap = 64;
  }
  s.outlier_polish = o.precise_layout;  // the unconstrained stage's, as the settings above
  s.seed = o.seed;
  s.threads = o.threads;
  return s;
}

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// FNV-1a digest (16 hex digits) of the printed shape-defining options: recorded in
/// provenance so two maps can be compared for "made the same way".
inline std::string options_digest_hex(const std::string& printed) {
  std::uint64_t h = 1469598103934665603ULL;
  for (char c : printed) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

/// Centre of the bounding box and its diagonal; the stages work on (V - centre) / diagonal
/// so that every tolerance is relative to the model (stretch efficiency is scale-invariant).
struct Normalization {
  Eigen::RowVector3d centre = Eigen::RowVector3d::Zero();
  double diagonal = 0;  ///< 0 for a mesh of zero extent
};

inline Normalization bounding_box_normalization(const RowMat3d& V) {
  Normalization n;
  Eigen::RowVector3d lo = V.colwise().minCoeff(), hi = V.colwise().maxCoeff();
  // Halves first: lo + hi would overflow for coordinates beyond DBL_MAX / 2 (same bits
  // otherwise, halving is exact).
  n.centre = 0.5 * lo + 0.5 * hi;
  const Eigen::RowVector3d extent = hi - lo;
  n.diagonal = extent.norm();
  // The squared length overflows for meshes beyond ~1e154 across (the diagonal became inf
  // and every normalized position 0) and underflows below ~1e-154 (a mesh 1e-200 across
  // looked like a point). There, divide by the longest side first; elsewhere norm() keeps
  // the bits every existing map was made with.
  if (!(n.diagonal > 1e-150 && n.diagonal < 1e150)) {
    const double side = extent.cwiseAbs().maxCoeff();
    if (side > 0 && side <= std::numeric_limits<double>::max()) n.diagonal = side * (extent / side).norm();
  }
  return n;
}

/// SolverFailed unless a map's measures are finite: a result never reports a valid map with
/// NaN or infinite stretch.
inline Status require_finite_measures(double efficiency, double l2_stretch, double linf_stretch) {
  if (std::isfinite(efficiency) && std::isfinite(l2_stretch) && std::isfinite(linf_stretch)) return Status();
  char buf[160];
  std::snprintf(buf, sizeof buf, "the stretch of the map is not finite (efficiency %g, L2 %g, Linf %g)", efficiency,
                l2_stretch, linf_stretch);
  return Status(ErrorCode::SolverFailed, buf);
}

}  // namespace spherekit::detail
