// Morph sequences between consistent remeshes, blended in a feature-aligned frame (see
// morph.h for the formula and why the endpoints are copied rather than evaluated).
#include "spherekit/convert/morph.h"

#include <cmath>
#include <string>

namespace spherekit::convert {

TriMesh morph_frame(const TriMesh& a, const TriMesh& b, double t, const Similarity& alignment) {
  if (t == 0) return a;
  if (t == 1) return TriMesh{b.V, a.F};
  TriMesh out{RowMat3d(a.V.rows(), 3), a.F};
  if (alignment.is_identity()) {
    out.V = (1 - t) * a.V + t * b.V;
    return out;
  }
  const Similarity to_a = alignment.inverse();  // B's frame -> A's frame
  const Similarity carry = alignment.interpolated(t);
  for (Eigen::Index v = 0; v < a.V.rows(); ++v) {
    const Eigen::Vector3d pa = a.V.row(v).transpose();
    const Eigen::Vector3d pb = to_a.apply(Eigen::Vector3d(b.V.row(v).transpose()));
    out.V.row(v) = carry.apply(Eigen::Vector3d((1 - t) * pa + t * pb)).transpose();
  }
  return out;
}

Result<MorphSequence> morph_sequence(const TriMesh& a, const TriMesh& b, const RowMat3d& features_a,
                                     const RowMat3d& features_b, const MorphOptions& options) {
  if (options.frames < 2)
    return Status(ErrorCode::InvalidArgument, "a morph needs at least 2 frames, got " + std::to_string(options.frames));
  if (a.V.rows() == 0 || a.F.rows() == 0) return Status(ErrorCode::InvalidInput, "empty mesh A");
  if (a.V.rows() != b.V.rows() || a.F.rows() != b.F.rows() || a.F != b.F)
    return Status(ErrorCode::InvalidInput, "A and B do not have the same connectivity (" + std::to_string(a.V.rows()) +
                                               " and " + std::to_string(b.V.rows()) +
                                               " vertices): morph consistent remeshes of one collection");
  if (!a.V.allFinite() || !b.V.allFinite()) return Status(ErrorCode::InvalidInput, "non-finite vertex position");
  if (features_a.rows() != features_b.rows())
    return Status(ErrorCode::InvalidArgument, std::to_string(features_a.rows()) + " features on A but " +
                                                  std::to_string(features_b.rows()) + " on B");
  MorphSequence out;
  if (options.align && features_a.rows() > 0) {
    SPHEREKIT_ASSIGN_OR_RETURN(out.alignment, fit_similarity(features_a, features_b, options.with_scale));
    out.aligned = true;
    const RowMat3d back = out.alignment.inverse().apply(features_b);
    out.alignment_rms = std::sqrt((back - features_a).squaredNorm() / static_cast<double>(features_a.rows()));
  }
  for (int k = 0; k < options.frames; ++k) {
    // k / (frames - 1) is exactly 0 and 1 at the ends.
    const double t = static_cast<double>(k) / static_cast<double>(options.frames - 1);
    out.times.push_back(t);
    out.frames.push_back(morph_frame(a, b, t, out.alignment));
  }
  return out;
}

}  // namespace spherekit::convert
