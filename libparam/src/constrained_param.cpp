// The constrained spherical parameterization stage (Asirvatham, Praun, Hoppe 2005 §4):
//   check -> fill holes -> normalize -> path network (arcs on the sphere, paths on the mesh)
//   -> progressive mesh keeping the features, collapsing path vertices only along their paths
//   (its base is exactly the feature triangulation) -> base on the target points ->
//   coarse-to-fine refinement with the features fixed -> Steiner vertices removed -> final
//   pass on the input connectivity -> measure.
#include "spherekit/constrained_param.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include <Eigen/SVD>

#include "detail/feature_warp.h"
#include "detail/path_network.h"
#include "detail/rotation.h"
#include "detail/kernel_point.h"
#include "detail/sphere_embedding.h"
#include "detail/stage_util.h"
#include "detail/untangle_patch.h"
#include "spherekit/check_mesh.h"
#include "spherekit/fill_holes.h"
#include "spherekit/metrics.h"
#include "spherekit/predicates.h"
#include "spherekit/progressive_mesh.h"
#include "spherekit/version.h"

namespace spherekit {
namespace {

using detail::seconds_since;

std::string options_digest(const ConstrainedParamOptions& o) {
  char buf[384];
  const auto& s = o.sphere;
  std::snprintf(buf, sizeof buf,
                "reg=%.17g;hole=%.17g;hshape=%.17g;seed=%llu;effort=%d;steiner=%.17g;angle=%.17g;ext=%.17g;side=%d;"
                "unswirl=%d;flips=%d;arc=%d",
                s.regularizer_weight, s.hole_weight, s.hole_shape_weight, static_cast<unsigned long long>(s.seed),
                s.effort, o.steiner_penalty, o.min_angle_deg, o.extremity_fraction, o.sidedness ? 1 : 0,
                o.unswirl ? 1 : 0, o.edge_flips ? 1 : 0, o.arc_ranking ? 1 : 0);
  // Appended only when set, so that the digests of maps made without it stay as they were.
  std::string text = buf;
  if (o.as_unconstrained) text += ";asu=1";
  return detail::options_digest_hex(text.c_str());
}

double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// A mutable face set with vertex-face incidence, for undoing the network's edge splits.
struct FaceSet {
  std::vector<std::array<int, 3>> F;
  std::vector<char> alive;
  std::vector<std::vector<int>> vf;
  void detach(int f) {
    for (int v : F[static_cast<size_t>(f)]) {
      auto& l = vf[static_cast<size_t>(v)];
      l.erase(std::find(l.begin(), l.end(), f));
    }
  }
  void attach(int f) {
    for (int v : F[static_cast<size_t>(f)]) vf[static_cast<size_t>(v)].push_back(f);
  }
  detail::PatchMesh patch() const { return {&F, &vf}; }
  bool flipped(const RowMat3d& S, int f) const {
    const auto& c = F[static_cast<size_t>(f)];
    return orient3d_origin(S.row(c[0]).data(), S.row(c[1]).data(), S.row(c[2]).data()) <= 0;
  }
};

constexpr int kMaxFailedFolds = 8;  // folds left flipped while undoing splits, before giving up
constexpr long kUntangleWork = 4'000'000;  // subgradient steps per untangling call (~0.2 s)

// Local untangling: moves the free corners of the given flipped faces (and, when that is not
// enough, vertices in growing rings around them) to points inside their spherical kernels.
// A vertex whose kernel is empty stays, unless `soft`: then it goes to its best compromise
// point (see kernel_point), which lets a fold that no single vertex can undo unfold over
// successive sweeps. Returns true when no face around them is flipped any more.
bool untangle(const FaceSet& fs, const std::vector<char>& fixed, std::vector<int> bad, RowMat3d* S,
              bool soft = false) {
  // A fold that the sweeps cannot undo would otherwise keep them busy for minutes (growing
  // rings, a full subgradient run per vertex with an empty kernel): the work is bounded, in
  // subgradient steps, so that the caller's next remedy gets its turn.
  long work = 0;
  for (int sweep = 0; sweep < 120 && !bad.empty() && work < kUntangleWork; ++sweep) {
    std::vector<int> corners;
    for (int f : bad)
      for (int v : fs.F[static_cast<size_t>(f)]) corners.push_back(v);
    const std::vector<int> cand = detail::grow_rings(fs.patch(), std::move(corners), sweep / 6);
    for (int v : cand) {
      if (fixed[static_cast<size_t>(v)]) continue;
      std::vector<std::array<int, 2>> ring;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (int f : fs.vf[static_cast<size_t>(v)]) {
        const auto& c = fs.F[static_cast<size_t>(f)];
        int k = c[0] == v ? 0 : c[1] == v ? 1 : 2;
        int a = c[static_cast<size_t>((k + 1) % 3)], b = c[static_cast<size_t>((k + 2) % 3)];
        ring.push_back({a, b});
        mean += S->row(a).transpose();
      }
      Eigen::Vector3d x, y;
      if (!(mean.norm() > 0)) continue;
      if (detail::kernel_point(*S, ring, mean, &x, soft ? &y : nullptr, &work)) S->row(v) = x.transpose();
      else if (soft) S->row(v) = y.transpose();
    }
    std::vector<int> still;
    for (int v : cand)
      for (int f : fs.vf[static_cast<size_t>(v)])
        if (fs.flipped(*S, f)) still.push_back(f);
    std::sort(still.begin(), still.end());
    still.erase(std::unique(still.begin(), still.end()), still.end());
    bad.swap(still);
  }
  return bad.empty();
}

std::vector<int> flipped_faces(const FaceSet& fs, const RowMat3d& S) {
  std::vector<int> bad;
  for (size_t f = 0; f < fs.F.size(); ++f)
    if (fs.alive[f] && fs.flipped(S, static_cast<int>(f))) bad.push_back(static_cast<int>(f));
  return bad;
}

// The flipped faces around the given faces (within `rings` rings of their corners).
std::vector<int> flipped_near(const FaceSet& fs, const RowMat3d& S, const std::vector<int>& around, int rings) {
  std::vector<int> corners;
  for (int f : around)
    for (int v : fs.F[static_cast<size_t>(f)]) corners.push_back(v);
  std::vector<int> bad;
  for (int v : detail::grow_rings(fs.patch(), std::move(corners), rings))
    for (int f : fs.vf[static_cast<size_t>(v)])
      if (fs.flipped(S, f)) bad.push_back(f);
  std::sort(bad.begin(), bad.end());
  bad.erase(std::unique(bad.begin(), bad.end()), bad.end());
  return bad;
}

// Untangling of a fold left by undoing a split (a thin input face whose two Steiner-split
// halves bulged across a path comes back inverted). Moving the fold's corners one at a time
// into their kernels (untangle) repairs it fast but leaves slivers, which the stretch
// optimizer afterwards cannot open (armadillo with 64 features: efficiency 0.07 instead of
// 0.28); untangling the patch around it as a whole in a planar chart (detail::untangle_patch)
// gives shapes close to the input's. So small patches come first; then the vertex-by-vertex
// untangling, enough where a small patch is boxed in by its fixed outline; then larger
// patches; last the soft untangling, which moves corners with empty kernels to their best
// compromise points (on failure S is restored: a soft sweep may have spread the fold).
bool untangle_fold(const FaceSet& fs, const std::vector<Eigen::Vector3d>& X, const std::vector<char>& fixed,
                   const std::vector<int>& bad, RowMat3d* S) {
  for (int rings : {1, 2})
    if (detail::untangle_patch(fs.patch(), X, fixed, bad, rings, S)) return true;
  const RowMat3d saved = *S;
  if (untangle(fs, fixed, bad, S)) return true;
  *S = saved;
  for (int rings : {4, 8, 16})
    if (detail::untangle_patch(fs.patch(), X, fixed, bad, rings, S)) return true;
  if (untangle(fs, fixed, bad, S, /*soft=*/true)) return true;
  *S = saved;
  return false;
}

// Undoes the network's edge splits in reverse order on the map: each undo merges two pairs of
// faces back into the input's; if a merged face flips (its quad was not convex on the
// sphere), the neighbourhood is untangled before the next undo. Returns the number of
// undos that needed untangling, or -1 if a face stays flipped at the end or more than
// kMaxFailedFolds undos could not be untangled on the way.
int remove_steiner_vertices(const detail::PathNetwork& net, const std::vector<char>& fixed_all, RowMat3d* S) {
  FaceSet fs;
  fs.F = net.F;
  fs.alive.assign(fs.F.size(), 1);
  fs.vf.resize(net.X.size());
  for (size_t f = 0; f < fs.F.size(); ++f) fs.attach(static_cast<int>(f));
  int untangled = 0, failed = 0;
  for (size_t i = net.splits.size(); i-- > 0;) {
    const auto& sp = net.splits[i];
    std::vector<int> merged;
    for (int t = 0; t < 2; ++t) {
      int f = sp.f[static_cast<size_t>(t)], g = sp.g[static_cast<size_t>(t)];
      if (f < 0) continue;
      fs.detach(g);
      fs.alive[static_cast<size_t>(g)] = 0;
      fs.detach(f);
      fs.F[static_cast<size_t>(f)] = sp.old[static_cast<size_t>(t)];
      fs.attach(f);
      if (fs.flipped(*S, f)) merged.push_back(f);
    }
    if (!merged.empty()) {
      ++untangled;
      // A face left flipped here may still be merged again below; but a map where folds
      // keep failing is not going to be repaired, and each failure costs seconds: give up
      // early so that the caller can try another network.
      if (!untangle_fold(fs, net.X, fixed_all, merged, S) && ++failed > kMaxFailedFolds) return -1;
    }
  }
  // Whatever is still flipped at the end: untangle once more over the final faces, fold by
  // fold.
  std::vector<int> bad = flipped_faces(fs, *S);
  for (size_t guard = 2 * bad.size() + 8; !bad.empty(); --guard) {
    if (guard == 0) return -1;
    std::vector<int> seed = flipped_near(fs, *S, {bad.front()}, 3);
    if (!untangle(fs, fixed_all, seed, S) && !untangle_fold(fs, net.X, fixed_all, flipped_near(fs, *S, seed, 3), S))
      return -1;
    bad = flipped_faces(fs, *S);
  }
  return untangled;
}

}  // namespace

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr const char* kSteinerFailure = "a face stays flipped after removing the path network's Steiner vertices";
// The point of a Fibonacci lattice on the unit sphere (4096 points, about 0.055 rad apart)
// whose smallest angle to the targets is largest (the first such point; any point if there
// are no targets): where an auxiliary feature goes.
Eigen::Vector3d farthest_lattice_point(const std::vector<Eigen::Vector3d>& targets) {
  constexpr int kPoints = 4096;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  std::vector<Eigen::Vector3d> unit;  // normalized once, not per lattice point
  for (const auto& t : targets) unit.push_back(t.normalized());
  Eigen::Vector3d best = Eigen::Vector3d::UnitZ();
  double best_cos = kInf;  // the largest dot product with a target, minimized
  for (int i = 0; i < kPoints; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / kPoints;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Eigen::Vector3d p(r * std::cos(golden * i), r * std::sin(golden * i), z);
    double c = -kInf;
    for (const auto& t : unit) c = std::max(c, p.dot(t));
    if (c < best_cos) {
      best_cos = c;
      best = p;
    }
  }
  return best;
}

// Vertex optimizations per free vertex after which a pass of this stage counts as not
// converging (normal maps: at most about 31; OptimizerSettings::max_pass_work).
constexpr double kConstrainedPassWork = 100;

// `steiner_failure` is set when the attempt failed only because a face stayed flipped after
// the Steiner vertices were removed: the one failure another network variant may avoid.
// `network_subset` (indices into the features; empty: all) are the features the path network
// triangulates; the others are then carried onto their targets by the feature warp
// (detail/feature_warp.h: dense feature sets).
Result<ConstrainedParamResult> constrained_attempt(const TriMesh& mesh, const std::vector<int>& feature_vertices,
                                                   const std::vector<Eigen::Vector3d>& targets_in,
                                                   const ConstrainedParamOptions& options, const ProgressFn& progress,
                                                   bool* steiner_failure, const std::vector<int>& network_subset,
                                                   std::vector<int>* warp_culprits = nullptr) {
  const auto t_start = std::chrono::steady_clock::now();
  ConstrainedParamResult result;
  const SphereParamOptions& so = options.sphere;
  if (so.effort < 0 || so.effort > 5) return Status(ErrorCode::InvalidArgument, "effort must be in 0..5");
  if (feature_vertices.size() != targets_in.size())
    return Status(ErrorCode::InvalidArgument, "need one target per feature (" + std::to_string(feature_vertices.size()) +
                                                  " features, " + std::to_string(targets_in.size()) + " targets)");
  const int k_given = static_cast<int>(feature_vertices.size());
  for (int i = 0; i < k_given; ++i) {
    int v = feature_vertices[static_cast<size_t>(i)];
    if (v < 0 || v >= mesh.V.rows())
      return Status(ErrorCode::InvalidInput, "feature " + std::to_string(i) + " names vertex " + std::to_string(v) +
                                                 ", out of range (mesh has " + std::to_string(mesh.V.rows()) + ")");
    const Eigen::Vector3d& t = targets_in[static_cast<size_t>(i)];
    if (!t.allFinite() || std::abs(t.norm() - 1) > 1e-6)
      return Status(ErrorCode::InvalidArgument, "target " + std::to_string(i) + " is not a unit vector");
    for (int j = 0; j < i; ++j) {
      if (feature_vertices[static_cast<size_t>(j)] == v)
        return Status(ErrorCode::InvalidInput, "features " + std::to_string(j) + " and " + std::to_string(i) +
                                                   " are on the same vertex " + std::to_string(v));
      if (angle_between(targets_in[static_cast<size_t>(j)], t) < 1e-7)
        return Status(ErrorCode::InvalidInput, "targets " + std::to_string(j) + " and " + std::to_string(i) +
                                                   " coincide (closer than 1e-7 rad)");
    }
  }
  std::vector<Eigen::Vector3d> targets;
  for (const auto& t : targets_in) targets.push_back(t.normalized());

  // 1. Check and close holes (as the unconstrained stage does).
  MeshCheck check = check_mesh(mesh);
  SPHEREKIT_RETURN_IF_ERROR(require_param_accepts(mesh, check, /*allow_boundary=*/true));
  SPHEREKIT_ASSIGN_OR_RETURN(FilledMesh filled, fill_holes(mesh));
  result.holes_filled = filled.holes;
  const TriMesh& closed = filled.mesh;
  const int n = static_cast<int>(closed.V.rows());
  const int nf = static_cast<int>(closed.F.rows());
  result.times.check = seconds_since(t_start);

  // Normalize (centre, unit bounding-box diagonal) as the unconstrained stage does. The
  // measures are taken on the normalized mesh too: stretch sums over the input's own
  // coordinates overflow or underflow far from unit size, and the measures do not depend on
  // scale.
  const detail::Normalization nz = detail::bounding_box_normalization(closed.V);
  const double diag = nz.diagonal;
  if (!(diag > 0)) return Status(ErrorCode::InvalidInput, "mesh has zero extent");
  RowMat3d Pn = (closed.V.rowwise() - nz.centre) / diag;
  TriMesh unit;
  unit.V = Pn;
  unit.F = closed.F;

  auto finish_measure = [&](const RowMat3d& S, const std::vector<int>& fv) -> Status {
    result.flipped_faces = count_flipped_faces(closed.F, S);
    std::vector<char> real(static_cast<size_t>(nf), 0);
    for (int f = 0; f < filled.original_faces; ++f) real[static_cast<size_t>(f)] = 1;
    SPHEREKIT_ASSIGN_OR_RETURN(SphereMapMetrics m, evaluate_sphere_map(unit, S, {}, &real));
    result.efficiency = m.efficiency;
    result.l2_stretch = m.l2_stretch;
    result.linf_stretch = m.linf;
    result.winding = m.winding;
    SPHEREKIT_RETURN_IF_ERROR(detail::require_finite_measures(m.efficiency, m.l2_stretch, m.linf));
    result.max_feature_angle = 0;
    for (int i = 0; i < k_given; ++i)
      result.max_feature_angle = std::max(
          result.max_feature_angle,
          angle_between(S.row(fv[static_cast<size_t>(i)]).transpose(), targets_in[static_cast<size_t>(i)].normalized()));
    result.map.S = S.topRows(filled.original_vertices);
    result.map.provenance.library_version = kVersion;
    result.map.provenance.method = "constrained";
    result.map.provenance.options_digest = options_digest(options);
    result.map.provenance.seed = so.seed;
    result.times.total = seconds_since(t_start);
    return Status();
  };

  // 2. Few features: start from the unconstrained map.
  std::vector<int> fv = feature_vertices;
  const bool need_unconstrained = k_given < 4 || !detail::targets_surround_origin(targets);
  if (need_unconstrained) {
    SphereParamOptions uo = so;
    uo.align_rotation = false;
    SPHEREKIT_ASSIGN_OR_RETURN(SphereParamResult u, parameterize_sphere(mesh, uo, progress));
    if (u.flipped_faces != 0) return Status(ErrorCode::SolverFailed, "unconstrained map is not bijective");
    // Rotate the map so the features come closest to their targets.
    std::vector<Eigen::Vector3d> from;
    for (int v : fv) from.push_back(u.map.S.row(v).transpose());
    Eigen::Matrix3d R = k_given > 0 ? detail::best_rotation(from, targets) : Eigen::Matrix3d::Identity();
    RowMat3d S0 = u.map.S * R.transpose();
    S0.rowwise().normalize();
    if (k_given <= 1) {
      // One feature: the rotated map puts it on its target up to rounding; snap it exactly
      // and keep the result if the exact check still passes.
      RowMat3d S1 = S0;
      if (k_given == 1) S1.row(fv[0]) = targets[0].transpose();
      if (count_flipped_faces(mesh.F, S1) == 0) {
        result.flipped_faces = 0;
        // The input's own faces (no hole faces) at the normalized positions.
        TriMesh open;
        open.V = Pn.topRows(filled.original_vertices);
        open.F = mesh.F;
        SPHEREKIT_ASSIGN_OR_RETURN(SphereMapMetrics m, evaluate_sphere_map(open, S1));
        result.efficiency = m.efficiency;
        result.l2_stretch = m.l2_stretch;
        result.linf_stretch = m.linf;
        result.winding = m.winding;
        SPHEREKIT_RETURN_IF_ERROR(detail::require_finite_measures(m.efficiency, m.l2_stretch, m.linf));
        result.max_feature_angle = k_given ? angle_between(S1.row(fv[0]).transpose(), targets[0]) : 0.0;
        result.map.S = S1;
        result.map.provenance.library_version = kVersion;
        result.map.provenance.method = "constrained";
        result.map.provenance.options_digest = options_digest(options);
        result.map.provenance.seed = so.seed;
        result.times.total = seconds_since(t_start);
        return result;
      }
    }
    // Auxiliary features, until the targets surround the origin: each target is the point of
    // a fixed spherical lattice farthest from every target so far, a function of the targets
    // alone, and its feature the vertex the rotated unconstrained map puts nearest to it (a
    // move within about one triangle). So the meshes of a collection, mapped to the same
    // targets (steps 2 and 6), get the same auxiliary targets and path networks of the same
    // layout. Before, each mesh took its own farthest vertex with its own target: ICT heads
    // with landmarks on the face only got networks that differed around that feature, one
    // path winding round to 2.5x its shortest route, correspondence error 0.049-0.058.
    std::vector<char> used(static_cast<size_t>(filled.original_vertices), 0);
    for (int v : fv) used[static_cast<size_t>(v)] = 1;
    while (static_cast<int>(fv.size()) < 4 || !detail::targets_surround_origin(targets)) {
      if (fv.size() >= static_cast<size_t>(k_given) + 8 || fv.size() >= static_cast<size_t>(filled.original_vertices))
        return Status(ErrorCode::SolverFailed, "could not complete the feature set with auxiliary features");
      const Eigen::Vector3d aim = farthest_lattice_point(targets);
      int best = -1;
      double best_d = kInf;
      for (int v = 0; v < filled.original_vertices; ++v) {
        if (used[static_cast<size_t>(v)]) continue;
        const double d = (S0.row(v).transpose() - aim).squaredNorm();
        if (d < best_d) {
          best_d = d;
          best = v;
        }
      }
      used[static_cast<size_t>(best)] = 1;
      fv.push_back(best);
      targets.push_back(aim);
    }
    result.network.auxiliary_features = static_cast<int>(fv.size()) - k_given;
  }
  // The features the network triangulates: all, or the dense set's subset (never with
  // auxiliary features, which only sparse sets get).
  std::vector<int> net_fv = fv;
  std::vector<Eigen::Vector3d> net_targets = targets;
  const bool warp = !network_subset.empty() && !need_unconstrained;
  if (warp) {
    net_fv.clear();
    net_targets.clear();
    for (int i : network_subset) {
      net_fv.push_back(fv[static_cast<size_t>(i)]);
      net_targets.push_back(targets[static_cast<size_t>(i)]);
    }
  }
  const int k = static_cast<int>(net_fv.size());

  // 3.-4. Path network on the normalized mesh Pn (made above).
  auto t0 = std::chrono::steady_clock::now();
  detail::NetworkOptions no;
  no.steiner_penalty = options.steiner_penalty;
  no.min_angle_deg = options.min_angle_deg;
  no.extremity_fraction = options.extremity_fraction;
  no.sidedness = options.sidedness;
  no.unswirl = options.unswirl;
  no.edge_flips = options.edge_flips;
  no.arc_ranking = options.arc_ranking;
  SPHEREKIT_ASSIGN_OR_RETURN(detail::PathNetwork net, detail::build_path_network(Pn, closed.F, net_fv, net_targets, no, progress));
  result.times.network = seconds_since(t0);
  auto& rep = result.network;
  rep.paths = static_cast<int>(net.paths.size());
  rep.total_length = net.total_length * diag;
  rep.max_ratio = net.max_ratio;
  rep.swirls_fixed = net.swirls_fixed;
  rep.edge_flips = net.edge_flips;
  rep.deferred = net.deferred;
  rep.steiner_vertices = static_cast<int>(net.steiner_parent.size());
  rep.arc_targets = net_targets;
  for (const auto& p : net.paths) {
    rep.arcs.push_back({p.a, p.b});
    std::vector<Eigen::Vector3d> line;
    for (int v : p.verts) line.push_back(net.X[static_cast<size_t>(v)] * diag + nz.centre.transpose());
    rep.polylines.push_back(std::move(line));
  }

  // 5. Constrained progressive mesh of the network mesh: its base is the triangulation.
  t0 = std::chrono::steady_clock::now();
  const int nn = static_cast<int>(net.X.size());
  const int nnf = static_cast<int>(net.F.size());
  RowMatXd Pnet(nn, 3);
  for (int v = 0; v < nn; ++v) Pnet.row(v) = net.X[static_cast<size_t>(v)].transpose();
  RowMat3i Fnet(nnf, 3);
  for (int f = 0; f < nnf; ++f)
    for (int c = 0; c < 3; ++c) Fnet(f, c) = net.F[static_cast<size_t>(f)][static_cast<size_t>(c)];
  ProgressiveMeshOptions pmo;
  pmo.keep_vertices.assign(static_cast<size_t>(nn), 0);
  for (int v : net_fv) pmo.keep_vertices[static_cast<size_t>(v)] = 1;
  for (const auto& p : net.paths)
    for (size_t i = 1; i < p.verts.size(); ++i) pmo.constraint_edges.push_back({p.verts[i - 1], p.verts[i]});
  pmo.target_vertices = k;
  if (options.as_unconstrained) {  // the unconstrained stage's simplification (sphere_param.cpp)
    pmo.normal_weight = 0.02;
    pmo.memoryless = true;
  }
  SPHEREKIT_ASSIGN_OR_RETURN(ProgressiveMesh pm, build_progressive_mesh(Pnet, Fnet, pmo, progress));
  if (static_cast<int>(pm.base_vertices.size()) != k || static_cast<int>(pm.base_faces.size()) != 2 * k - 4)
    return Status(ErrorCode::SolverFailed, "constrained simplification did not reach the feature triangulation");
  result.times.simplify = seconds_since(t0);

  // 6. Coarse-to-fine refinement with the features fixed on their targets.
  t0 = std::chrono::steady_clock::now();
  detail::OptimizerSettings settings = detail::optimizer_settings(so);
  settings.edge_frame_cruft = options.as_unconstrained;  // false: the collection stages' energy (stretch_optimizer.cpp, singular_cruft_term)
  settings.measured_normalization = options.as_unconstrained;
  // Targets that force a poor map (a network winding round between features) can keep the
  // optimizer busy for many minutes at every level; such a map fails here, deterministically,
  // and the collection's step 6 falls back to its step-2 maps (OptimizerSettings::max_pass_work).
  settings.max_pass_work = kConstrainedPassWork;
  std::vector<double> wnet(static_cast<size_t>(nnf), 1.0), snet(static_cast<size_t>(nnf), 0.0);
  for (int f = 0; f < nnf; ++f)
    if (net.face_origin[static_cast<size_t>(f)] >= filled.original_faces) {
      wnet[static_cast<size_t>(f)] = so.hole_weight;
      snet[static_cast<size_t>(f)] = so.hole_shape_weight;
    }
  detail::EmbedInput in;
  in.P = &Pnet;
  in.pm = &pm;
  in.face_weight = wnet;
  in.face_shape_weight = snet;
  in.base_positions = RowMat3d::Zero(nn, 3);
  in.fixed.assign(static_cast<size_t>(nn), 0);
  for (int i = 0; i < k; ++i) {
    in.base_positions.row(net_fv[static_cast<size_t>(i)]) = net_targets[static_cast<size_t>(i)].transpose();
    in.fixed[static_cast<size_t>(net_fv[static_cast<size_t>(i)])] = 1;
  }
  // The network mesh gets the full final passes although another runs on the input
  // connectivity below: a map relaxed only coarse-to-fine keeps needle-shaped regions along
  // the paths, and merging their Steiner vertices away there folds faces that no local
  // untangling repairs (armadillo with 64 features).
  const bool has_steiner = nn > n;
  RowMat3d Snet;
  SPHEREKIT_RETURN_IF_ERROR(detail::embed_coarse_to_fine(in, settings, progress, &Snet, nullptr));

  // 7. Drop the Steiner vertices: the input's faces are unions of network faces, valid as
  //    long as each split edge's quad stays convex on the sphere (checked exactly).
  RowMat3d S = Snet.topRows(n);
  std::vector<char> fixed(static_cast<size_t>(n), 0);
  for (int v : net_fv) fixed[static_cast<size_t>(v)] = 1;
  // The final passes on the input connectivity: its hole faces weighted as the network's.
  std::vector<double> w(static_cast<size_t>(nf), 1.0), sw(static_cast<size_t>(nf), 0.0);
  for (int f = filled.original_faces; f < nf; ++f) {
    w[static_cast<size_t>(f)] = so.hole_weight;
    sw[static_cast<size_t>(f)] = so.hole_shape_weight;
  }
  const RowMatXd P = Pn;
  if (has_steiner) {
    // Rarely, a split edge's quad is not convex on the sphere and a merged face flips: the
    // neighbourhood is untangled (features stay fixed), then the final pass smooths it out.
    std::vector<char> fixed_net(static_cast<size_t>(nn), 0);
    for (int v : net_fv) fixed_net[static_cast<size_t>(v)] = 1;
    RowMat3d Sw = Snet;
    int untangled = remove_steiner_vertices(net, fixed_net, &Sw);
    if (untangled < 0) {
      *steiner_failure = true;
      return Status(ErrorCode::SolverFailed, kSteinerFailure);
    }
    result.network.flips_after_steiner_removal = untangled;
    S = Sw.topRows(n);
    if (int flips = count_flipped_faces(closed.F, S); flips != 0)
      return Status(ErrorCode::Internal, std::to_string(flips) + " faces flipped after removing Steiner vertices");
    SPHEREKIT_RETURN_IF_ERROR(detail::optimize_in_place(P, closed.F, w, sw, fixed, settings, progress, &S));
  }
  if (warp) {
    // 8. Dense sets: the features outside the network's subset flow onto their targets
    //    (bijective at every step, exact predicate), then the final pass with all fixed.
    detail::WarpStats ws;
    std::vector<Eigen::Vector3d> from;
    for (int v : fv) from.push_back(S.row(v).transpose());
    std::vector<char> all_fixed(static_cast<size_t>(n), 0);
    for (int v : fv) all_fixed[static_cast<size_t>(v)] = 1;
    // Where the flow stalls (features passing close to each other squeeze the mesh between
    // them), one stretch pass with every feature held where it is spreads the mesh out again.
    // Measured on faust5k 000 + 013 with 128 landmarks: the stage failed after 17 network
    // variants (the growing networks' Steiner vertices could not be removed), 7 minutes; with
    // the relaxation the second network's warp completes, 17 s.
    detail::OptimizerSettings relax_settings = settings;
    relax_settings.final_iter = 1;
    const detail::WarpRelaxFn relax = [&](RowMat3d* Sr) {
      return detail::optimize_in_place(P, closed.F, w, sw, all_fixed, relax_settings, progress, Sr);
    };
    if (const Status wst = detail::warp_features_to_targets(Pn, closed.F, fv, targets, progress, &S, &ws, relax); !wst.ok()) {
      if (warp_culprits) {
        // The features the warp could not carry, and those whose arcs pass others: the
        // next network routes its paths through them.
        *warp_culprits = detail::passing_features(from, targets);
        warp_culprits->insert(warp_culprits->end(), ws.culprits.begin(), ws.culprits.end());
      }
      return wst;
    }
    result.network.warped_features = static_cast<int>(fv.size()) - k;
    result.network.warp_steps = ws.steps;
    SPHEREKIT_RETURN_IF_ERROR(detail::optimize_in_place(P, closed.F, w, sw, all_fixed, settings, progress, &S));
  }
  result.times.refine = seconds_since(t0);
  SPHEREKIT_RETURN_IF_ERROR(finish_measure(S, fv));
  return result;
}

}  // namespace

Result<ConstrainedParamResult> parameterize_sphere_constrained(const TriMesh& mesh,
                                                               const std::vector<int>& feature_vertices,
                                                               const std::vector<Eigen::Vector3d>& targets,
                                                               const ConstrainedParamOptions& options,
                                                               const ProgressFn& progress) {
  // Removing the Steiner vertices can leave a face flipped that local untangling cannot
  // repair (a non-convex quad next to fixed features). A network routed with another
  // Steiner cost puts them elsewhere: retry a few deterministic variants before failing.
  const double factors[] = {1.0, 0.75, 1.5, 0.6, 2.5};
  Status last;
  int attempt = 0;
  // Dense sets (detail/feature_warp.h): first a network on a well-spread subset and the warp
  // for the rest; only if that fails, the network over all features as for sparse sets.
  if (static_cast<int>(feature_vertices.size()) > detail::kDenseFeatureThreshold) {
    // The warp fails where features would have to pass others on their way: a network that
    // constrains only its subset leaves the other features where stretch puts them, in places
    // on the far side of a network feature or of each other (faust5k, 64 landmarks: a
    // feature 0.24 rad from its target whose arc runs within 0.002 rad of a network
    // feature). Those features join the network (paths then route them, on the right side)
    // and the attempt is repeated. A network whose Steiner vertices cannot be removed goes on
    // to the next size, which routes other paths; other Steiner costs are not tried
    // (measured on faust5k with 64 and 128 landmarks: a subset that failed with one cost
    // failed with all three, at 10-25 s each).
    for (int size : detail::kDenseNetworkSizes) {
      std::vector<int> subset = detail::spread_subset(targets, size);
      ConstrainedParamOptions o = options;
      o.steiner_penalty = std::max(1.05, options.steiner_penalty);
      for (int grow = 0; grow < detail::kDenseGrowRounds; ++grow) {
        bool steiner_failure = false;
        std::vector<int> culprits;
        Result<ConstrainedParamResult> r =
            constrained_attempt(mesh, feature_vertices, targets, o, progress, &steiner_failure, subset, &culprits);
        ++attempt;
        if (r.ok()) {
          r.value().network.attempts = attempt;
          return r;
        }
        const ErrorCode c = r.status().code();
        if (c == ErrorCode::Cancelled || c == ErrorCode::InvalidInput || c == ErrorCode::InvalidArgument) return r.status();
        if (steiner_failure || culprits.empty()) break;
        subset.insert(subset.end(), culprits.begin(), culprits.end());
        std::sort(subset.begin(), subset.end());
        subset.erase(std::unique(subset.begin(), subset.end()), subset.end());
      }
    }
  }
  for (double f : factors) {
    ConstrainedParamOptions o = options;
    o.steiner_penalty = std::max(1.05, options.steiner_penalty * f);
    bool steiner_failure = false;
    Result<ConstrainedParamResult> r = constrained_attempt(mesh, feature_vertices, targets, o, progress, &steiner_failure, {});
    ++attempt;
    if (r.ok()) {
      r.value().network.attempts = attempt;
      return r;
    }
    last = r.status();
    if (!steiner_failure) return last;
  }
  return Status(ErrorCode::SolverFailed, std::string(kSteinerFailure) + " (after " + std::to_string(attempt) + " network variants)");
}

Result<double> own_unconstrained_efficiency(const TriMesh& mesh, const ConstrainedParamOptions& options,
                                            const ProgressFn& progress) {
  SphereParamOptions so = options.sphere;
  so.align_rotation = false;  // the efficiency does not depend on it
  SPHEREKIT_ASSIGN_OR_RETURN(SphereParamResult u, parameterize_sphere(mesh, so, progress));
  return u.efficiency;
}

// Why a retry, not the unconstrained stage's settings everywhere (issue 19, session 41): on a
// generated limb shape (stress_meshes 3801 draw 7, member 0) mapped to its own unconstrained
// map's feature images, a target the unconstrained optimum meets exactly, the collection
// stages' settings reach efficiency 0.134 against 0.212 unconstrained; with as_unconstrained
// 0.182 (the normal-weighted quadrics keep the limbs at the coarse levels, the edge-frame
// anti-cruft and measured energy let the optimizer spread them). In whole collections (4
// members, consistent + refinement) it raised every member's efficiency there (0.13 -> 0.15-
// 0.18) but, used for every map, moved the correspondence error the wrong way on most other
// families (faust5k 0.022/0.034/0.020 -> 0.024/0.036/0.023, ict_heads 0.006/0.008/0.006 ->
// 0.007/0.009/0.010, three of five generated families 3-11% worse): so only maps that keep too
// little of their own efficiency are made again.
Result<ConstrainedParamResult> constrained_param_or_retry(const TriMesh& mesh, const std::vector<int>& feature_vertices,
                                                          const std::vector<Eigen::Vector3d>& targets,
                                                          const ConstrainedParamOptions& options,
                                                          double unconstrained_efficiency, double retry_below,
                                                          const ProgressFn& progress) {
  Result<ConstrainedParamResult> first = parameterize_sphere_constrained(mesh, feature_vertices, targets, options, progress);
  if (!first.ok() || options.as_unconstrained || !(retry_below > 0) || !(unconstrained_efficiency > 0) ||
      first->efficiency >= retry_below * unconstrained_efficiency)
    return first;
  ConstrainedParamOptions o = options;
  o.as_unconstrained = true;
  Result<ConstrainedParamResult> second = parameterize_sphere_constrained(mesh, feature_vertices, targets, o, progress);
  if (!second.ok() && second.status().code() == ErrorCode::Cancelled) return second.status();
  const double first_efficiency = first->efficiency;
  Result<ConstrainedParamResult> kept =
      second.ok() && second->efficiency > first_efficiency ? std::move(second) : std::move(first);
  kept.value().efficiency_retried = true;
  kept.value().first_efficiency = first_efficiency;
  kept.value().as_unconstrained = kept->efficiency > first_efficiency;
  return kept;
}

}  // namespace spherekit
