// Coarse-to-fine embedding of a progressive mesh on the sphere (Praun & Hoppe 2003 §4).
#pragma once

#include <vector>

#include "detail/sphere_state.h"
#include "spherekit/progress.h"
#include "spherekit/progressive_mesh.h"
#include "spherekit/status.h"

namespace spherekit::detail {

struct EmbedInput {
  const RowMatXd* P = nullptr;          ///< #V by 3m surface positions
  const ProgressiveMesh* pm = nullptr;  ///< its progressive mesh
  std::vector<double> face_weight;      ///< energy weight per face (empty = 1)
  std::vector<double> face_shape_weight;  ///< weight of the scale-free shape term per face (empty = 0)
  /// Sphere positions of the base vertices (#V rows, only base rows read); empty = map the
  /// base tetrahedron to a regular tetrahedron inscribed in the unit sphere.
  RowMat3d base_positions;
  std::vector<char> fixed;              ///< vertices never moved by the optimizer (empty = none)
};

struct EmbedStats {
  int passes = 0;             ///< global passes run
  int rounds = 0;             ///< rounds over all passes
  int fallback_placements = 0;  ///< splits where the kernel centroid was not strictly inside
};

/// Embeds the base, replays every vertex split placing the new vertex inside its kernel and
/// optimizing, and runs global passes on a geometric schedule plus a final one.
/// S receives #V by 3 unit vectors. Errors: Cancelled, SolverFailed (empty kernel).
Status embed_coarse_to_fine(const EmbedInput& in, const OptimizerSettings& s, const ProgressFn& progress,
                            RowMat3d* S, EmbedStats* stats);

/// Final optimization of a complete mesh whose map S is already valid (#V by 3, bijective),
/// `fixed` vertices standing still: the coarse-to-fine machinery on a progressive mesh
/// without collapses runs just its final passes (s.final_iter). Errors as above.
Status optimize_in_place(const RowMatXd& P, const RowMat3i& F, const std::vector<double>& face_weight,
                         const std::vector<double>& shape_weight, const std::vector<char>& fixed,
                         const OptimizerSettings& s, const ProgressFn& progress, RowMat3d* S);

}  // namespace spherekit::detail
