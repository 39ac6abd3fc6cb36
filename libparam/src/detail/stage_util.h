// Small pieces every parameterization stage shares: timing, the provenance digest of its
// shape-defining options, and the normalization of the input. Internal to libparam.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
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
  n.centre = 0.5 * (lo + hi);
  n.diagonal = (hi - lo).norm();
  return n;
}

}  // namespace spherekit::detail
