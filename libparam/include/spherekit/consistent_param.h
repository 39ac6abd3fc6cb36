// Consistent spherical parameterization of a collection (Asirvatham, Praun, Hoppe 2005 §3):
// n genus-0 meshes with corresponding feature vertices are mapped onto one sphere so that
// corresponding features land on the same sphere points. Two surface points of different
// meshes then correspond when their sphere points are equal (correspondence.h).
//
// The six steps of the paper:
//   1. unconstrained map of the reference mesh; its feature images are F';
//   2. constrained maps of the other meshes to F';
//   3. every mesh remeshed as an octahedral geometry image (identical connectivity), the grid
//      samples nearest to F' snapped onto the features;
//   4. the remeshes concatenated into one mesh with vertices in R^{3n};
//   5. unconstrained map of that mesh (n-D quadric simplification, stretch summed over the
//      n geometries); the images of the snapped samples are the final locations F;
//   6. constrained maps of every mesh to F.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "spherekit/constrained_param.h"
#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/refine_correspondence.h"
#include "spherekit/status.h"

namespace spherekit {

struct ConsistentParamOptions {
  /// Settings of every constrained map (steps 2 and 6); its `sphere` member also drives the
  /// unconstrained maps of steps 1 and 5. Shape-defining.
  ConstrainedParamOptions constrained;
  int reference = 0;          ///< mesh whose unconstrained map gives F' (step 1). Shape-defining.
  /// Side N (2^k+1) of the step-3 remesh grid; the joint mesh of step 5 has about N^2
  /// vertices. Step 5 only decides where the k features go, a low-frequency layout: 65^2
  /// (4098 vertices, over 100 per feature for k up to 40) resolves it, and the time of
  /// step 5 grows with N^2 * n. Shape-defining.
  int remesh_size = 65;
  /// false: stop after step 2 (every mesh constrained to the reference's feature images; the
  /// reference keeps its unconstrained map). For comparisons and quick previews.
  bool refine_locations = true;
  /// After step 6, refine the correspondence (refine_correspondence.h): every other mesh's
  /// map is fitted to the reference's, so that the maps agree between the features too, not
  /// only at them. Its template is `reference`; its threads are `threads`. Shape-defining.
  bool refine_correspondence = true;
  RefineCorrespondenceOptions refinement;
  /// A constrained map of steps 2 and 6 keeping less than this fraction of its mesh's
  /// unconstrained stretch efficiency is made again as the unconstrained stage simplifies and
  /// optimizes (constrained_param_or_retry), the more efficient kept; every member's
  /// unconstrained map is then made once (step 1's for the reference). 0: no retry, no
  /// unconstrained maps. 0.8 is the floor the collection's maps are held to (issue 19).
  /// Shape-defining.
  double efficiency_retry = 0.8;
  /// Worker threads in total (0 = hardware). Steps 2 and 6 map several meshes at once.
  /// Effort only: the result is the same for any value.
  int threads = 0;
};

/// Wall-clock seconds per step (the paper's Table 1 columns).
struct ConsistentParamTimes {
  double reference = 0;      ///< step 1
  double initial = 0;        ///< step 2
  double remesh = 0;         ///< step 3
  double concatenate = 0;    ///< step 4
  double joint = 0;          ///< step 5
  double final_maps = 0;     ///< step 6
  double refinement = 0;     ///< correspondence refinement (after step 6)
  double total = 0;
};

struct ConsistentParamResult {
  /// One map per mesh (step 6; after step 2 when refine_locations is false, where the
  /// reference's entry is its unconstrained map with network.paths == 0).
  std::vector<ConstrainedParamResult> maps;
  std::vector<Eigen::Vector3d> initial_locations;  ///< F' (step 1), one per feature
  std::vector<Eigen::Vector3d> final_locations;    ///< F (step 5); equal to F' without refinement
  double reference_efficiency = 0;  ///< step 1 map's stretch efficiency
  /// Per mesh: its unconstrained map's stretch efficiency (the reference's is step 1's; all 0
  /// when efficiency_retry is 0), what the retry compares against.
  std::vector<double> unconstrained_efficiency;
  double joint_efficiency = 0;      ///< step 5: efficiency of the summed stretch (0 if not run)
  int joint_flips = 0;              ///< step 5 map's flipped faces (exact predicate; 0)
  int remesh_vertices = 0;          ///< vertices of the joint mesh (0 if not run)
  /// Non-empty when step 6 failed for some mesh (a constrained map to F could not be
  /// completed, e.g. its path network's Steiner vertices could not be removed, or it was
  /// completed keeping less than 0.7x its step-2 map's stretch efficiency): the result
  /// then falls back to the step-2 maps (every feature on F', still consistent) and this
  /// holds the reason; `rejected_locations` holds the F that was tried.
  std::string refinement_failure;
  /// The same as values: the mesh that could not be mapped to F, and why (without the
  /// "mesh i: " of refinement_failure); -1 and empty when step 6 succeeded.
  int refinement_failure_mesh = -1;
  std::string refinement_failure_reason;
  std::vector<Eigen::Vector3d> rejected_locations;
  /// The correspondence refinement, when it ran (members empty otherwise).
  RefineCorrespondenceResult refinement;
  ConsistentParamTimes times;
};

/// Replaces `map`'s sphere map by `S` (a refined map of the same mesh, refine_correspondence.h)
/// and recomputes its measures (flips, efficiency, stretch, winding, feature angle against
/// `locations`, one per entry of `feature_vertices`). Errors: those of evaluate_sphere_map().
Status replace_refined_map(const TriMesh& mesh, const std::vector<int>& feature_vertices,
                           const std::vector<Eigen::Vector3d>& locations, RowMat3d S, ConstrainedParamResult* map);

/// Which mesh an error of parameterize_consistent() concerns, as a value: callers name the
/// mesh their way (its file, its member name) without reading the message.
struct MeshFailure {
  int mesh = -1;  ///< index into `meshes`; -1: the collection as a whole (sizes, options)
  Status reason;  ///< the error without the "mesh i: " the returned Status starts with
};

/// Maps n >= 1 meshes consistently. `features[i][k]` is the vertex of mesh i that is
/// feature k; every mesh has the same number of features (at least 1; 4 or more for
/// a path network without auxiliary features, see parameterize_sphere_constrained).
/// Errors name the mesh ("mesh 2: ..."): InvalidArgument (sizes, options), InvalidInput (a
/// mesh not genus 0, two features on one vertex, ...), SolverFailed (a path network could
/// not be completed), Cancelled. `failure`, when given, receives which mesh an error
/// concerns and why.
/// Deterministic: same input and options give the same bits, for any thread count.
Result<ConsistentParamResult> parameterize_consistent(const std::vector<TriMesh>& meshes,
                                                      const std::vector<std::vector<int>>& features,
                                                      const ConsistentParamOptions& options = {},
                                                      const ProgressFn& progress = {}, MeshFailure* failure = nullptr);

}  // namespace spherekit
