// Correspondence refinement of a consistent collection (issue 19; a stage after step 6 of
// Asirvatham, Praun & Hoppe 2005 §3). Consistent maps agree exactly at the features and
// drift between them: each member's map minimizes its own stretch, and nothing asks the
// maps to agree away from the features. This stage makes every member's map agree with
// one template member's map intrinsically:
//
//   - the template's vertices are given positions q_v on the sphere seen through member i's
//     map (start: the template's own sphere points, i.e. today's correspondence); they name
//     surface points Y_v = S_i^-1(q_v) of member i;
//   - fit: the q_v move so that the template, carried onto member i by Y, is as rigid as
//     possible (ARAP energy of the template's cotangent metric, Sorkine & Alexa 2007):
//     rotations per vertex, then one Levenberg-damped Gauss-Newton step with every point
//     moving in the tangent plane of member i's surface, then each point walks on the
//     surface to the point nearest its stepped position. All points move at once; the
//     points of a template face that would be inverted on the sphere (exact predicate) go
//     back, so q always describes a bijection psi of the sphere
//     (template faces carried from their own sphere triangles to q); features stay fixed;
//   - flow: the fitted correspondence is exact but rough at the template's triangle scale
//     (points stop where a move would invert a face), and psi^-1 composed with
//     member i's map inherits that roughness as stretch. So psi^-1 is taken only at a few
//     hundred well-spread member vertices, and member i's map flows onto those targets with
//     the constrained stage's feature warp (smooth compactly supported radial-basis flow,
//     every step checked with the exact predicate; feature_warp.h), the features standing
//     still: bijective, features exact, smooth;
//   - polish: a few final passes of the stretch optimizer (features fixed) take out the
//     stretch the flow leaves between its samples; they converge locally, so the agreement
//     at the scale of the samples stays (measured: FAUST efficiency back to 0.93-0.99x the
//     members' own, the correspondence error unchanged or lower);
//   - a few rounds of fit, flow and polish, each from the previous map; a round whose map would
//     fall below 0.8x the starting efficiency (see RefinedMember) is not taken.
//
// Why one template and not a consensus of all members: `add` brings one new member into a
// collection whose maps are fixed, and transfer, morphs and PCA read correspondence from one
// member to the others; fitting to the reference serves both, at (n-1) independent jobs.
// For isometric collections (poses of one body) the rigid fit is the true correspondence; for
// others it is the least-distorting one between template and member.
#pragma once

#include <string>
#include <vector>

#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/status.h"

namespace spherekit {

struct RefineCorrespondenceOptions {
  int template_mesh = 0;  ///< the member whose metric the others are fitted to. Shape-defining.
  int iterations = 40;    ///< fit iterations (local + global step) per round. Shape-defining.
  /// Levenberg damping of the fit's step, relative to the rigidity term's scale (keeps a
  /// step short where the energy is flat). Shape-defining.
  double damping = 0.01;
  /// Fit-and-flow rounds; each starts from the previous round's map. Shape-defining.
  int rounds = 3;
  /// Member vertices (farthest-point samples) whose fitted partners the map flows onto in
  /// the first round. Shape-defining.
  int samples = 256;
  /// Each later round flows onto this many times the samples the round before carried, up
  /// to max_samples (256, 512, 512; a flow that fails halves its count). 1 = the same count
  /// every round, as collections refined before it were (their manifests have no entry).
  /// Shape-defining.
  int sample_growth = 2;
  /// The most samples a grown round takes (never fewer than `samples`). Shape-defining.
  int max_samples = 512;
  /// A grown round takes at most one sample per this many member vertices (never fewer than
  /// `samples`): denser samples than that ask the flow for detail at the triangles' own
  /// scale, where it fails. Shape-defining.
  int vertices_per_sample = 8;
  /// Final passes of the stretch optimizer after each flow (features fixed, the unconstrained
  /// stage's weights): they take out the stretch the flow leaves between its samples. 0 =
  /// none. Shape-defining.
  int stretch_passes = 3;
  /// Sweeps moving each member vertex from the flow's map toward its fitted partner (as far
  /// as its faces stay positive and at least half their size) before the stretch passes: the
  /// flow carries the fit at its samples only, and the passes, converging locally, keep more
  /// of the fit between them when they start nearer to it. 0 = none, as collections refined
  /// before it were (their manifests have no entry). Shape-defining.
  int snap_sweeps = 3;
  /// Per mesh, the stretch efficiency of its own unconstrained map, where known (0 or no
  /// entry: unknown). A round is taken only if it leaves at least 0.8x the lower of this
  /// (else the member's starting efficiency) and the template's.
  std::vector<double> own_efficiency;
  int threads = 0;  ///< members refined at once (0 = hardware). Effort only.
};

/// What happened to one member's map.
struct RefinedMember {
  bool refined = false;  ///< the map was replaced
  std::string note;      ///< why it was not (template, holes, no valid blend), else empty
  /// Distortion of the template carried onto this member: the area-weighted mean symmetric
  /// Dirichlet energy of the template's faces (4 for an isometry; it grows without bound as
  /// a face collapses), before the first round and after the last round taken; crushed
  /// faces (over a member's hole, or squeezed below about 1/10 of their size across some
  /// direction or stretched 10x along one: density above 100) are left out and counted in
  /// crushed_faces.
  double energy_before = 0, energy_after = 0;
  int crushed_faces = 0;  ///< template faces left out of energy_after
  int rounds = 0;        ///< fit-and-flow rounds taken
  int samples = 0;       ///< samples of the last round taken
  /// Samples of the last round taken left out because the fit folds the member's map around
  /// them (only after the flow failed with every sample count; 0 otherwise).
  int folded_samples_left_out = 0;
  /// Stretch passes the flows of the rounds taken made where a flow stalled (features and
  /// samples held; the flow then went on).
  int flow_relaxations = 0;
  /// Vertex moves toward the fitted partners (snap_sweeps) in the rounds taken.
  int snap_moves = 0;
  /// Stretch efficiency of the member's map before and after (metrics.h). A round that
  /// would leave less than 0.8x the lower of the member's own unconstrained efficiency (its
  /// starting efficiency where that is not known) and the template's is not taken (agreeing
  /// maps carry the template's distortion).
  double efficiency_before = 0, efficiency_after = 0;
  double seconds = 0;
};

struct RefineCorrespondenceResult {
  std::vector<RefinedMember> members;  ///< one per mesh; the template's has refined = false
  double seconds = 0;
};

/// Refines the sphere maps `maps` (one #V by 3 array per mesh, consistent: feature k of
/// every mesh on the same sphere point) in place. `features[i][k]` is mesh i's vertex of
/// feature k. The template's map is not changed. Holes are allowed: template points that
/// fall in a member's hole stay where they are, member samples that fall in a template's
/// hole get no target. A member whose flow fails keeps its map (note says why).
/// Errors: InvalidArgument (sizes, template index, options), Cancelled.
/// Deterministic for any thread count.
Result<RefineCorrespondenceResult> refine_correspondence(const std::vector<TriMesh>& meshes,
                                                         const std::vector<std::vector<int>>& features,
                                                         std::vector<RowMat3d>& maps,
                                                         const RefineCorrespondenceOptions& options = {},
                                                         const ProgressFn& progress = {});

}  // namespace spherekit
