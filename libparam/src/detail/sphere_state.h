// The mutable state of a coarse-to-fine spherical embedding: the current level of a
// progressive mesh with a position on the unit sphere for every alive vertex.
// Internal to libparam.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "spherekit/mesh.h"

namespace spherekit::detail {

class WorkerPool;

struct SphereState {
  const RowMatXd* P = nullptr;  ///< #V by 3m surface positions (m models; m = 1 normally)
  int models = 1;
  std::vector<std::array<int, 3>> F;  ///< current corners of every face (ids stable)
  std::vector<char> face_alive;
  std::vector<double> face_weight;    ///< energy weight per face (hole faces: small)
  /// Weight of the scale-free shape (MIPS) term per face; empty = 0. Hole faces carry it so
  /// that they may shrink freely but not degenerate into slivers that pin their neighbours.
  std::vector<double> face_shape_weight;
  std::vector<std::vector<int>> vf;   ///< alive faces around each vertex
  RowMat3d S;                         ///< sphere position of every vertex (alive ones valid)
  std::vector<char> vertex_alive;
  std::vector<char> fixed;            ///< vertices the optimizer must not move (features)
  int alive_vertices = 0;
  std::vector<double> model_area;     ///< total surface area per model at the current level
  std::vector<double> area_floor;     ///< per model: minimum energy weight area of a face
  /// area_floor as a fraction of the mean face area (update_areas; OptimizerSettings::area_floor_rel).
  double area_floor_rel = 1e-3;
  std::vector<double> average_face_area;  ///< per model: model_area / alive faces
  std::vector<double> model_scale;    ///< per model: 4 pi / model_area (surface rescaled to the sphere's area)

  double hole_area_penalty = 0;       ///< lambda per unit chord area of real faces (see update_hole_area_penalty)
  /// The penalty also without holes: the full-resolution pass, whose energy is the measured
  /// one, set by the refiner (see update_hole_area_penalty).
  bool chord_area_penalty = false;
  /// Anti-cruft term: mean over the three edge frames (true) or w * g^-3 with g the smallest
  /// squared singular value (false); see stretch_optimizer.cpp.
  bool edge_frame_cruft = true;

  /// Recomputes model_area (and the derived scales and the hole-area penalty) over the alive faces.
  void update_areas();
  void update_hole_area_penalty();
};

/// The coarse levels of the coarse-to-fine refinement: up to this many vertices a level is
/// optimized each time #V grows by sqrt(nv_ratio) instead of nv_ratio (as the reference
/// implementation does), and large faces there take the accordion split from about 8 degrees
/// (split_distance) instead of fine_split_distance. These levels decide the global layout.
inline constexpr int kCoarseLevelVertices = 1000;

/// Per-effort settings of the optimizer (Praun & Hoppe 2003's schedule; the numbers are
/// the reference implementation's presets, REFERENCE.md §2.5).
struct OptimizerSettings {
  int line_search_iter = 10;   ///< energy evaluations per 1-D search
  int vsplit_vt_iter = 2;      ///< local optimizations of each inserted vertex
  int vsplit_nei_iter = 0;     ///< local optimizations of its neighbours
  int global_iter = 3;         ///< passes (rounds until no vertex is active) per level
  int final_iter = 3;          ///< passes at full resolution (on the measured energy)
  /// After the final pass, move the vertices of faces stretched more than 10x the 99th
  /// percentile to lower their rings' largest stretch (Refiner::polish_outlier_faces).
  bool outlier_polish = false;
  double movetol = 1e-3;       ///< a vertex stays active while its credit exceeds this
  double movetol_rel = 0;      ///< if > 0: threshold = min(movetol, movetol_rel * shortest chord to a neighbour)
  /// Coarse layout precision (SphereParamOptions::precise_layout): levels of at most
  /// precise_vertices vertices (the final pass excepted) judge activity with
  /// precise_movetol_rel instead of movetol_rel for the first precise_rounds rounds of each
  /// pass. 0 = off.
  int precise_vertices = 0;
  double precise_movetol_rel = 0;
  int precise_rounds = 0;
  /// If > 0: the split_distance of the level passes above fine_split_vertices vertices (the
  /// final pass keeps its own). SphereParamOptions::precise_layout sets 0.95 above
  /// kCoarseLevelVertices.
  double fine_split_distance = 0;
  int fine_split_vertices = 0;
  /// Every face's energy weight is its surface area plus this fraction of the mean face area
  /// (SphereState::area_floor_rel). SphereParamOptions::precise_layout sets 0.03 for the
  /// coarse-to-fine levels; the final pass takes the default, the measured objective.
  double area_floor_rel = 1e-3;
  double nv_ratio = 1.2;       ///< a level is optimized each time #V grows by this factor
  double regularizer_weight = 1e-4;
  /// Faces whose chord plane passes closer than this to the centre (large spherical
  /// triangles) are evaluated with Praun & Hoppe's accordion split; the final full-resolution
  /// pass sets 0.25, so that only slivers along a great circle are split there and every other
  /// face is measured on its chord triangle, as the efficiency is. 0.99 splits
  /// every face wider than about 8 degrees (circumradius), i.e. all faces of the coarse
  /// levels, where the layout of thin limbs is decided: there the bulge of a spherical
  /// triangle over its chord is large, and leaving it out (0.9: only faces above 26
  /// degrees) let limbs end compressed (issue 20: tentacle blob 0.1252 -> 0.1327, the
  /// reference 0.1321).
  double split_distance = 0.99;
  bool newton = false;         ///< vertex moves by safeguarded Newton steps (else Brent searches)
  std::uint64_t seed = 1;
  int threads = 0;             ///< 0 = hardware concurrency
  int max_rounds = 2000;       ///< safety cap on rounds per pass
  /// If > 0: a pass that needs more than this many vertex optimizations per free vertex (at
  /// least kMinPassWorkVertices vertices' worth) is not converging, and the stage fails
  /// (SolverFailed) instead of going on. Measured on normal inputs (unconstrained maps of the
  /// generated limb shapes, FAUST and ICT collections): at most 31 per vertex on passes over
  /// 200 vertices; the constrained stage sets 100. A step-6 map of ICT heads whose features
  /// were left out (no head top, no neck corners) needed 230-520 per vertex on every pass
  /// from 700 vertices on, and had not finished after 11 CPU minutes.
  double max_pass_work = 0;
  /// If > 0: a pass ends (without error) once it has done this many vertex optimizations per
  /// free vertex (at least kMinPassWorkVertices vertices' worth). Normal passes of the
  /// unconstrained stage need at most about 47 (the final pass of a generated standing figure
  /// with holes; 28-31 elsewhere); one level of that figure at resolution 72 crept on for 419
  /// per vertex (2000 rounds, a third of the map's CPU time) and left a worse layout than a
  /// pass cut at 64 (issue 20: efficiency 0.1951 -> 0.2065, CPU 12.3 -> 7.6 s).
  /// SphereParamOptions::precise_layout sets 64; the collection stages keep max_pass_work.
  double pass_work_cap = 0;
  bool coloured_rounds = false;  ///< rounds as colour classes (every computed move applied) instead of one greedy independent set
  bool edge_frame_cruft = true;  ///< SphereState::edge_frame_cruft for this stage (the collection stages set false)
  /// The full-resolution pass minimizes the measured stretch, normalized by the chord area
  /// the faces cover (SphereState::chord_area_penalty), also on meshes without holes.
  bool measured_normalization = false;
};

OptimizerSettings settings_for_effort(int effort);

/// An orthonormal tangent basis (e1, e2) at unit vector x, with e1 x e2 = x.
void tangent_basis(const Eigen::Vector3d& x, Eigen::Vector3d& e1, Eigen::Vector3d& e2);

/// Numerator of |J|_F^2 = a + c for the affine map taking domain edges e1, e2 to surface
/// edges d1, d2, from their Gram entries: |J|_F^2 = (E22 D11 + E11 D22 - 2 E12 D12) /
/// (E11 E22 - E12^2), the denominator being (2 * domain area)^2.
inline double gram_frobenius_numerator(double E11, double E22, double E12, double D11, double D22, double D12) {
  return E22 * D11 + E11 * D22 - 2 * E12 * D12;
}

/// Fields of a ring face's record in RingScratch::surf (one per face and model): the face
/// weight over the model's area, the area floor, the surface edge Gram entries |d1|^2,
/// |d2|^2, d1.d2 (d1 = pa - pv, d2 = pb - pv, pv the moving vertex's surface point), the
/// surface area, the shape-term weight. Only these: the energies, the accordion split
/// included, need no surface vector arithmetic while v moves (load_ring fills them).
enum SurfField : int { kSurfWeight = 0, kSurfFloor, kSurfG11, kSurfG22, kSurfG12, kSurfArea, kSurfShape };
inline constexpr size_t kSurfStride = 8;  ///< one cache line per record

/// Scratch memory for one vertex's 1-ring (one per thread).
struct alignas(64) RingScratch {
  struct Face {
    Eigen::Vector3d qa, qb;  ///< sphere points of the other two corners, ccw after v
    Eigen::Vector3d n;       ///< qa x qb: the kernel constraint n . x > 0
    int f;                   ///< face id
    int a, b;                ///< other corner vertex ids
    bool real;               ///< not a hole-filling face
  };
  std::vector<Face> faces;
  /// Per face and model, a record of kSurfStride doubles (fields SurfField): what the face's
  /// energy needs of the surface, constant while v moves.
  std::vector<double> surf;
  /// Per face and model, the energy at the vertex's current point and at a trial point
  /// (ring_energy's face_energy; the Newton steps reuse the current one).
  std::vector<double> energy_here, energy_trial;
};

/// Every alive vertex's ring as contiguous records, for a pass in which the connectivity
/// does not change (optimize_all): vertex v's faces are faces[start[v] .. start[v+1]), in
/// vf order, with their other corners ccw after v in corners[2 i], corners[2 i + 1]. The
/// rings are then read from one place instead of vf's separate allocations and the faces'
/// corner lists (cache misses were half of load_ring's time, issue 20).
struct RingIndex {
  std::vector<int> start, faces, corners;
};

/// The rings of st's current level (`pool` fills them in parallel; null: on this thread).
void build_ring_index(const SphereState& st, WorkerPool* pool, RingIndex* index);

/// Loads v's ring into scratch (from `index` if given, else from st.vf and st.F; the same
/// ring either way). Returns false if v has no faces.
bool load_ring(const SphereState& st, int v, RingScratch& ring, const RingIndex* index = nullptr);

/// Stretch energy of v's ring with v at sphere point x (+inf if a chord triangle degenerates).
/// Faces whose chord plane is closer to the centre than `split_distance` are evaluated with
/// the accordion split; 0 evaluates every face on its chord triangle (the measured energy).
/// `face_energy` (optional, faces x models) receives each face's energy per model, without
/// the hole-area term; complete only when the result is finite.
double ring_energy(const SphereState& st, const RingScratch& ring, const Eigen::Vector3d& x, double reg_weight,
                   double split_distance, double* face_energy = nullptr);

/// Gradient g and Hessian H of ring_energy at the unit point x on the chart
/// y(u, w) = normalize(x + u t1 + w t2) (t1, t2 an orthonormal tangent basis): analytic for
/// the faces evaluated on their chord triangle with edge-frame anti-cruft terms
/// (gram_derivatives.h), central differences of step h for the faces of the accordion split
/// (`energy_at_x`: ring_energy's face_energy at x, or null to recompute those).
/// Returns false where the energy is not finite or a derivative cannot be formed.
bool ring_tangent_derivatives(const SphereState& st, const RingScratch& ring, const Eigen::Vector3d& x,
                              const Eigen::Vector3d& t1, const Eigen::Vector3d& t2, double h, double reg_weight,
                              double split_distance, const double* energy_at_x, Eigen::Vector2d* g,
                              Eigen::Matrix2d* H);

/// True if every ring face is positively oriented with v at x, by exact predicate.
bool ring_valid_exact(const RingScratch& ring, const Eigen::Vector3d& x);

/// Up to `searches` kernel-constrained line searches (random great-circle direction, then
/// the perpendicular) from v's current position; `key` seeds the direction. Writes the
/// improved position to *out and returns true if the energy decreased (validity checked
/// exactly). Reads st only: safe to call concurrently for different vertices.
bool optimize_vertex(const SphereState& st, int v, std::uint64_t key, const OptimizerSettings& s,
                     RingScratch& ring, Eigen::Vector3d* out, int searches = 2, const RingIndex* index = nullptr);

/// A global pass (Praun & Hoppe 2003 / REFERENCE.md §2.5): rounds in which all active
/// vertices compute a move in parallel from the current positions, then moves are applied
/// greedily as an independent set (largest first). Deterministic for any thread count.
/// Returns the number of rounds, or -1 if cancelled by `keep_going`. `pool` runs the
/// candidate moves (null: on the calling thread only).
/// With s.max_pass_work > 0, a pass that exceeds that work ends early and sets
/// *work_exceeded (if given). `ring_cache` (optional): the level's RingIndex, built into it
/// when empty and reused by later passes over the same connectivity (the caller empties it
/// when the connectivity changes).
int optimize_all(SphereState& st, const OptimizerSettings& s, std::uint64_t pass_key,
                 const std::function<bool()>& keep_going, WorkerPool* pool = nullptr,
                 bool* work_exceeded = nullptr, RingIndex* ring_cache = nullptr);

/// The floor of OptimizerSettings::max_pass_work's budget, in vertices: coarse levels of a
/// few dozen vertices take up to 100 optimizations per vertex on normal inputs (FAUST, 33).
inline constexpr int kMinPassWorkVertices = 500;

}  // namespace spherekit::detail
