// Morphing between two members of a consistently parameterized collection (Asirvatham, Praun,
// Hoppe 2005, abstract and §5: consistent parameterizations serve morphing). The members'
// consistent remeshes (consistent_remesh.h) have identical connectivity and corresponding
// vertices, so a morph is an interpolation of vertex positions.
//
// Alignment. Two members may differ in position, orientation and size; a plain linear blend
// then shrinks and shears the in-between shapes (a turned head passes through a flattened
// one). With the members' corresponding features, the similarity H that best maps A's
// features onto B's (fit_similarity) separates the rigid part: the shapes are blended in A's
// frame and the blend is carried along the interpolated similarity,
//
//     frame(t) = H_t( (1 - t) A + t H^-1(B) ),    H_t = H interpolated from the identity,
//
// so the centroid of the features moves on a line, the shape turns about it at constant
// angular speed, and the size changes geometrically. At t = 0 this is A; at t = 1 it is B up
// to rounding. The endpoints are returned *exactly* (bit for bit the remeshes A and B): a
// morph must start and end on the members themselves, and t = 0 / t = 1 copy them instead of
// evaluating the formula. Without features (or with align = false) H is the identity and
// frame(t) = (1 - t) A + t B.
#pragma once

#include <vector>

#include "spherekit/convert/similarity_fit.h"
#include "spherekit/mesh.h"
#include "spherekit/status.h"

namespace spherekit::convert {

struct MorphOptions {
  int frames = 9;           ///< frames of the sequence including both ends (>= 2), t = k / (frames - 1)
  bool align = true;        ///< blend in an aligned frame when features are given (see above)
  bool with_scale = true;   ///< the alignment includes a uniform scale (else rigid)
};

/// A morph sequence.
struct MorphSequence {
  std::vector<double> times;    ///< t of each frame, 0 first, 1 last
  std::vector<TriMesh> frames;  ///< same faces as A; frames.front().V == A.V, frames.back().V == B.V exactly
  Similarity alignment;         ///< H (identity when not aligned)
  bool aligned = false;
  /// RMS distance between A's features and H^-1 of B's features (absolute units; 0 when not
  /// aligned): how well a similarity explains the features' difference.
  double alignment_rms = 0;
};

/// One frame: the formula above at parameter t (t = 0 returns A's positions and t = 1 B's,
/// exactly). `alignment` is H (identity: linear blend). Preconditions (asserted by
/// morph_sequence, not here): same vertex count.
TriMesh morph_frame(const TriMesh& a, const TriMesh& b, double t, const Similarity& alignment = {});

/// The sequence between two consistent remeshes.
/// @param features_a, features_b  #P by 3 corresponding feature positions on A and B (e.g. the
///        features' vertices on the original members), or empty for no alignment
/// Errors: InvalidArgument (frames < 2, features of different counts), InvalidInput (A and B
/// differ in vertex count or faces, empty, non-finite; features collinear: fit_similarity).
[[nodiscard]] Result<MorphSequence> morph_sequence(const TriMesh& a, const TriMesh& b, const RowMat3d& features_a,
                                                   const RowMat3d& features_b, const MorphOptions& options = {});

}  // namespace spherekit::convert
