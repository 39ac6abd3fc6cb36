// Unconstrained spherical parameterization (Praun & Hoppe 2003): progressive mesh down
// to a tetrahedron, regular tetrahedron on the sphere, coarse-to-fine vertex splits with
// kernel-constrained L2-stretch minimization. Bijective by construction and by check.
#pragma once

#include <cstdint>
#include <vector>

#include "spherekit/mesh.h"
#include "spherekit/progress.h"
#include "spherekit/sphere_map.h"
#include "spherekit/status.h"

namespace spherekit {

struct SphereParamOptions {
  // Shape-defining: changing these changes the answer (recorded in Provenance).
  /// Weight of the anti-cruft term w * min(a',c')^-3 (Praun & Hoppe 2003; stretch_optimizer.cpp).
  /// The term is not part of the measured stretch: it only keeps sphere triangles from
  /// ballooning over tiny surface regions. At the reference implementation's 1e-4 it held
  /// unconstrained maps well above their measured optimum (limbs, decimated meshes): 1e-5
  /// raised the efficiency on 35 of 39 meshes of four kinds by up to +0.029 (issue 20), the
  /// Linf stretch at most 1.25x the reference's; 1e-6 raised it further but let single faces
  /// stretch 1.5x the reference's Linf (horse). The collection stages keep 1e-4
  /// (kCollectionRegularizerWeight).
  double regularizer_weight = 1e-5;
  double hole_weight = 1e-5;         ///< stretch weight of faces added to close holes (they may shrink freely)
  /// Weight of a scale-free shape term on hole faces: they may shrink but not turn into
  /// slivers, which would pin the real faces along the hole's rim. Without it a large
  /// opening collapses (woody, one opening of 119 rim vertices in 694: 0.79 against the
  /// reference implementation's 0.90), but at 0.3 (the collection stages' weight,
  /// kCollectionHoleShapeWeight) it also held the rims in their 3-D shape: the ICT heads (four
  /// openings each) ended 0.001-0.005 below the reference. A tenth of it is still a barrier
  /// against slivers and leaves the rims free: measured on 21 meshes with holes (issue 20),
  /// higher efficiency on all 21 (woody 0.9717 -> 0.9921, head_s1 0.8224 -> 0.8266, bunny
  /// 0.7189 -> 0.7194, standing_r96-holes 0.3671 -> 0.3687).
  double hole_shape_weight = 0.03;
  std::uint64_t seed = 1;            ///< every random choice (line-search directions) derives from this
  bool align_rotation = true;        ///< rotate the result so face directions best match surface normals
  /// Coarse levels decide the global layout (Praun & Hoppe 2003 optimize coarse to fine over
  /// the progressive mesh), and the effort-2 convergence test, relative to the local chord
  /// length, stops them early: on smooth shapes the fine levels cannot move the layout back
  /// (igea 0.96170 against the reference implementation's 0.96176). With this set, levels of
  /// at most 3000 vertices are judged 4x more tightly in the first 10 rounds of each pass
  /// (bounded cost; limb shapes, which converge slowly, then go on at the usual tolerance),
  /// and the final pass makes 3 passes instead of 2. Measured over 40 meshes of four kinds
  /// (issue 20): below the reference on none (3 before), CPU +5% in all. Finer levels, whose
  /// layout is set, take the accordion split only on faces wider than about 18 degrees
  /// instead of 8 (the small obtuse faces the 8-degree test also caught cost ten times a
  /// plain face and measure the same to second order): the generated limb shapes 25-50% less
  /// CPU, efficiency within 0.002 (each still 0.013-0.029 above the reference). The levels
  /// also weight every face by its area plus 3% of the mean face area (the final pass by its
  /// area alone), so faces of tiny surface area are not squeezed freely while the layout is
  /// decided (bunny_planar Linf 10.1 -> 4.1, head_s4_dec4000 0.780 -> 0.835); and a pass ends
  /// after 64 vertex optimizations per vertex (normal passes need at most about 47; a creeping
  /// one took 419 on a generated standing figure with holes, standing_r72-holes 0.1951 ->
  /// 0.2065 in 60% of the time, no other of 54 stress meshes changed). The collection
  /// stages leave it off (collection_sphere_options()): their maps were measured without it.
  /// It also polishes outlier faces after the final pass: the vertices of a face stretched
  /// more than 10x the 99th percentile (a sliver of scan or iso-surface debris, which the L2
  /// energy weighs by its near-zero area) move within their kernels to lower their rings'
  /// largest stretch, spending at most 1e-7 of the L2 stretch energy over the sphere (generated shapes:
  /// quadruped_r96-holes Linf 1071 -> 10.8, biped_r160 110 -> 11.2, hand_r160 130 -> 17.4, each
  /// efficiency up by 3e-7..8e-6; the shared dev meshes have no such face and do not change).
  bool precise_layout = true;
  /// The progressive mesh's fine levels in parallel (ProgressiveMeshOptions::block_vertices):
  /// a mesh of at least 1.5 times this many vertices is first simplified in spatial blocks of
  /// about this many (two below twice this many), each by the same greedy on its own, its
  /// vertices next to another block held, until a fifth of their vertices remain in all (one cost cut for all blocks), in
  /// rounds while two blocks remain; then as one. The blocks depend on the mesh only
  /// (results do not depend on `threads`). The serial greedy
  /// was a quarter of igea's time with one thread and a third with two (issue 20); blocks
  /// also stay in cache: igea's simplification 1.9-2.1 -> 1.4 s with one thread, 1.8-1.95 ->
  /// 0.95-1.2 s with two; efficiency within -0.0022..+0.0020 of the single greedy on 24 meshes.
  /// 0: one greedy over the whole mesh. The collection stages leave it off
  /// (collection_sphere_options()): their maps were measured without it.
  int block_vertices = 8192;
  // Effort: changes only speed and accuracy.
  int effort = 2;                    ///< 0..5; expands to the presets in sphere_param.cpp
  int threads = 0;                   ///< worker threads for the optimization passes; 0 = hardware
};

/// The anti-cruft weight of the collection stages (constrained and consistent maps, their
/// unconstrained maps of steps 1 and 5, landmark proposals, the correspondence refinement's
/// stretch passes): the reference implementation's. Their feature paths, dense-set warps and
/// fallbacks were built and measured with it (issues 19, 25).
inline constexpr double kCollectionRegularizerWeight = 1e-4;

/// The hole faces' shape weight of the collection stages (as kCollectionRegularizerWeight:
/// their constrained paths, warps and refinement were measured with it).
inline constexpr double kCollectionHoleShapeWeight = 0.3;

/// SphereParamOptions with the collection stages' anti-cruft and hole shape weights, and no
/// coarse-layout precision.
inline SphereParamOptions collection_sphere_options() {
  SphereParamOptions o;
  o.regularizer_weight = kCollectionRegularizerWeight;
  o.hole_shape_weight = kCollectionHoleShapeWeight;
  o.precise_layout = false;
  o.block_vertices = 0;
  return o;
}

/// Wall-clock seconds spent in each part.
struct SphereParamTimes {
  double check = 0, simplify = 0, refine = 0, total = 0;
};

struct SphereParamResult {
  SphereMap map;                 ///< one unit vector per input vertex (holes' centre vertices removed)
  int flipped_faces = 0;         ///< faces with det <= 0 by the exact predicate: 0 for a bijection
  double efficiency = 0;         ///< stretch efficiency over the input's faces (metrics.h definition)
  double l2_stretch = 0, linf_stretch = 0;
  double winding = 0;            ///< closed inputs: signed area / 4 pi (+1)
  int holes_filled = 0;
  int base_vertices = 0;         ///< vertices of the progressive mesh base (4: tetrahedron)
  int optimization_passes = 0;   ///< global passes run
  SphereParamTimes times;
};

/// Maps a genus-0 triangle mesh (boundary loops allowed; they are filled with low-weight
/// faces) bijectively onto the unit sphere, minimizing the L2 stretch of sphere -> surface.
/// @param[in] mesh  genus-0, one component, manifold, finite (see check_mesh / require_genus0)
/// @return the map and its measures, or InvalidInput (not genus 0 ...), Cancelled, SolverFailed.
/// Deterministic: same input and options give the same bits, for any thread count.
/// Cost: about O(V log V) simplification plus a constant number of passes per level.
Result<SphereParamResult> parameterize_sphere(const TriMesh& mesh, const SphereParamOptions& options = {},
                                              const ProgressFn& progress = {});

}  // namespace spherekit
